"""`dump_qsr` writes what `parse_qsr` reads (learnt knowledge saved to a file)."""

import yaml

from conceptual_map.qsr import dump_qsr, load_qsr, parse_qsr


def test_dumped_knowledge_reads_back_the_same():
    knowledge = load_qsr()
    again = parse_qsr(yaml.safe_load(yaml.safe_dump(dump_qsr(knowledge))), "again")
    assert again.descriptions == knowledge.descriptions
    assert again.parameters == knowledge.parameters
    assert dict(again.fronts) == dict(knowledge.fronts)
    for name, model in knowledge.relations.items():
        assert abs(again.relations[name].mean - model.mean) < 1e-9
        assert abs(again.relations[name].std - model.std) < 1e-9
