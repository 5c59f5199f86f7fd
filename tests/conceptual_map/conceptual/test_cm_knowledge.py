"""Commonsense knowledge: the default file loads; bad files fail naming file and entry."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from conceptual_map.errors import KnowledgeError
from conceptual_map.knowledge import DEFAULT_KNOWLEDGE_PATH, load_knowledge
from conceptual_map.knowledge.loader import KnowledgeYamlLoader

WORLD_LABELS = ["cerealbox", "stapler", "whiteboardmarker", "table", "counter", "desk", "shelf",
                "monitor", "keyboard", "cup", "book"]


def _default_data() -> dict:
    return yaml.load(DEFAULT_KNOWLEDGE_PATH.read_text(), Loader=KnowledgeYamlLoader)


def _write(tmp_path: Path, data: dict) -> Path:
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_default_knowledge_has_categories_labels_and_consistent_tables():
    knowledge = load_knowledge()
    assert set(knowledge.categories) >= {"corridor", "kitchen", "office", "meeting_room",
                                         "living_room", "bathroom"}
    assert set(WORLD_LABELS) <= knowledge.labels
    assert knowledge.prior.sum() == pytest.approx(1.0)
    for model in knowledge.properties.values():
        np.testing.assert_allclose(model.table.sum(axis=1), 1.0)
    np.testing.assert_array_equal(knowledge.connectivity, knowledge.connectivity.T)
    assert ("cerealbox", "on", "table") in knowledge.relation_lambda


def test_relation_on_is_read_as_text_not_yaml_boolean():
    knowledge = load_knowledge()
    kitchen = knowledge.category_index("kitchen")
    assert knowledge.relation_lambda_of("cerealbox", "on", "table")[kitchen] == pytest.approx(0.5)


def test_user_file_is_used(tmp_path):
    data = _default_data()
    data["categories"]["kitchen"]["prior"] = 0.22
    data["categories"]["office"]["prior"] = 0.20
    knowledge = load_knowledge(_write(tmp_path, data))
    assert knowledge.prior[knowledge.category_index("kitchen")] == pytest.approx(0.22)
    assert knowledge.source.endswith("mine.yaml")


@pytest.mark.parametrize(
    ("change", "entry"),
    [
        (lambda d: d["properties"]["size"]["likelihood"]["kitchen"].update(small=0.9),
         "properties.size.likelihood.kitchen"),
        (lambda d: d["objects"]["lambda"]["table"].update(garage=1.0),
         "objects.lambda.table.garage"),
        (lambda d: d["objects"]["lambda"]["table"].update(kitchen=-1.0),
         "objects.lambda.table.kitchen"),
        (lambda d: d["relations"]["entries"][0].update(support="spaceship"),
         "relations.entries[0].support"),
        (lambda d: d["relations"]["entries"][0].update(relation="under"),
         "relations.entries[0].relation"),
        (lambda d: d["connectivity"]["pairs"].append(["kitchen", "attic", 1.0]),
         "connectivity.pairs[15]"),
        (lambda d: d["connectivity"]["pairs"].append(["kitchen", "office", 0.0]),
         "connectivity.pairs[15]"),
        (lambda d: d.pop("placeholders"), "top level"),
        (lambda d: d["categories"]["kitchen"].update(prior="high"), "categories.kitchen.prior"),
    ],
)
def test_invalid_entries_name_file_and_entry(tmp_path, change, entry):
    data = _default_data()
    change(data)
    path = _write(tmp_path, data)
    with pytest.raises(KnowledgeError) as info:
        load_knowledge(path)
    assert str(path) in str(info.value)
    assert entry in str(info.value)


def test_unreadable_and_malformed_files_are_knowledge_errors(tmp_path):
    with pytest.raises(KnowledgeError, match="cannot read"):
        load_knowledge(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("categories: [unclosed\n")
    with pytest.raises(KnowledgeError, match="not valid YAML"):
        load_knowledge(bad)
