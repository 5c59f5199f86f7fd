"""Room categories: one spelling, and a place classifier over a vocabulary of its own."""

import pytest
import yaml

from conceptual_map.knowledge import load_knowledge
from sim.errors import SimError
from sim.place_classifier import DEFAULT_CATEGORIES
from sim.scene import World
from sim.world_checks import check_world
from sim.world_file import parse_world
from sim.world_spec import normalise_category

BASE = """
name: one
size: [6.0, 4.0]
rooms:
  - {name: hall, category: CATEGORY, rect: [0.0, 0.0, 6.0, 4.0]}
robot: {model: pioneer, start: [3.0, 2.0, 0.0]}
"""


def parse_world_text(text: str):  # noqa: ANN201 - a WorldSpec
    spec = parse_world(yaml.safe_load(text), "test.yaml")
    check_world(spec)
    return spec


@pytest.mark.parametrize("written", ["meeting room", "Meeting-Room", " MEETING_room ",
                                     "meeting  room"])
def test_categories_are_normalised(written: str) -> None:
    assert normalise_category(written) == "meeting_room"
    spec = parse_world_text(BASE.replace("CATEGORY", f"'{written}'"))
    assert spec.rooms[0].category == "meeting_room"


def test_default_vocabulary_is_the_knowledge_base_s() -> None:
    assert set(DEFAULT_CATEGORIES) == set(load_knowledge().categories)


def test_one_category_building_gets_an_imperfect_classifier() -> None:
    """The confusion matrix spans the vocabulary, not the rooms this building has."""
    with World(parse_world_text(BASE.replace("CATEGORY", "kitchen")), seed=0) as world:
        classifier = world.robot.place_classifier
        assert set(classifier.categories) == set(DEFAULT_CATEGORIES)
        assert classifier.confusion["kitchen"]["kitchen"] < 1.0
        seen = {world.robot.classify_place().observed for _ in range(60)}
    assert len(seen) > 1 and seen <= set(DEFAULT_CATEGORIES)


def test_given_vocabulary_is_used_and_must_cover_the_rooms() -> None:
    spec = parse_world_text(BASE.replace("CATEGORY", "garage"))
    with pytest.raises(SimError, match=r"rooms\[0\] \(hall\): category 'garage' is not one"):
        World(spec, seed=0)
    with World(spec, seed=0, categories=["garage", "kitchen"]) as world:
        assert world.robot.place_classifier.categories == ["garage", "kitchen"]
