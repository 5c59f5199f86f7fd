"""The uninformed prior of a label the knowledge does not list, and support relations (on and
in) of a label."""

import numpy as np
import pytest
import yaml

from conceptual_map.conceptual import ConceptualMap
from conceptual_map.errors import KnowledgeError
from conceptual_map.knowledge import DEFAULT_KNOWLEDGE_PATH, UnknownLabelModel, load_knowledge
from conceptual_map.knowledge.loader import KnowledgeYamlLoader


def test_an_unknown_label_gets_the_same_rate_in_every_category_spread_over_supports():
    knowledge = load_knowledge()
    assert "bottle" not in knowledge.labels
    model = knowledge.unknown
    assert model == UnknownLabelModel(rate=0.5, room_share=0.5,
                                      supports=("table", "counter", "desk", "shelf"))
    with_bottle = knowledge.with_label("bottle")
    assert "bottle" in with_bottle.labels and "bottle" not in knowledge.labels
    np.testing.assert_allclose(with_bottle.room_lambda("bottle"), 0.25)
    np.testing.assert_allclose(with_bottle.total_room_lambda("bottle"), 0.5)  # uninformed
    on_table = with_bottle.relation_lambda_of("bottle", "on", "table")
    for support in model.supports:  # one lambda per support instance, whatever its label
        np.testing.assert_array_equal(with_bottle.relation_lambda_of("bottle", "on", support),
                                      on_table)
    assert with_bottle.category_index("office") == knowledge.category_index("office")
    assert knowledge.with_label("cup") is knowledge  # listed: unchanged
    cmap = ConceptualMap(with_bottle)  # the conceptual map takes it as any label
    cmap.graph.add_room("r")  # a room's own lambda, under the building-rate prior Gamma(a, a)
    a = with_bottle.rate_shape
    assert cmap.p_object_at("bottle", "r") == pytest.approx(1 - (a / (a + 0.25)) ** a)


def test_the_knowledge_file_sets_the_uninformed_prior(tmp_path):
    data = yaml.load(DEFAULT_KNOWLEDGE_PATH.read_text(), Loader=KnowledgeYamlLoader)
    data["unknown_labels"] = {"rate": 1.0, "room_share": 1.0}
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(data))
    knowledge = load_knowledge(path).with_label("bottle")
    np.testing.assert_allclose(knowledge.room_lambda("bottle"), 1.0)
    data["unknown_labels"] = {"supports": ["spaceship"]}
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(KnowledgeError, match="unknown_labels.supports"):
        load_knowledge(path)
    data["unknown_labels"] = {"rate": 0.0}
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(KnowledgeError, match="unknown_labels.rate"):
        load_knowledge(path)


def test_support_relations_list_in_as_well_as_on():
    knowledge = load_knowledge()
    relations = knowledge.support_relations("cup")
    assert relations["shelf"] == ("in",) and relations["table"] == ("on",)
    kitchen = knowledge.category_index("kitchen")
    assert knowledge.support_lambda("cup", "shelf")[kitchen] == pytest.approx(1.5)
    assert knowledge.support_lambda("cerealbox", "shelf")[kitchen] == pytest.approx(0.6)
    assert not knowledge.support_lambda("cup", "sofa").any()


def test_the_knowledge_file_says_how_often_labels_are_moved(tmp_path):
    """`mobility`: a sighting's chance to hold after `days` is exp(-rate x days); labels
    moved less often than `fixed_below` are furniture (the building memory keeps them)."""
    mobility = load_knowledge().mobility
    assert mobility.fixed("desk") and mobility.fixed("fridge")
    assert not mobility.fixed("cup") and not mobility.fixed("chair")
    assert mobility.rate("cup") == mobility.default  # not listed: the default rate
    assert mobility.still_there("cup", 2.0) == pytest.approx(np.exp(-2.0 * mobility.default))
    assert mobility.still_there("shelf", 100.0) == 1.0
    data = yaml.load(DEFAULT_KNOWLEDGE_PATH.read_text(), Loader=KnowledgeYamlLoader)
    path = tmp_path / "mine.yaml"
    for bad, where in (({"rate": {"unicorn": 0.1}}, "mobility.rate.unicorn"),
                       ({"rate": {"cup": -1}}, "mobility.rate.cup"),
                       ({"default": "often"}, "mobility.default"),
                       ({"speed": 1}, "mobility")):
        path.write_text(yaml.safe_dump({**data, "mobility": bad}))
        with pytest.raises(KnowledgeError, match=where.replace(".", r"\.")):
            load_knowledge(path)
    path.write_text(yaml.safe_dump({k: v for k, v in data.items() if k != "mobility"}))
    assert load_knowledge(path).mobility.rate("desk") == load_knowledge(path).mobility.default
