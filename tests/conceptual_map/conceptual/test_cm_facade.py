"""ConceptualMap query API: evidence moves room beliefs the right way."""

import pytest

from conceptual_map.conceptual import BPStatus, ConceptualMap
from conceptual_map.knowledge import load_knowledge


def _room() -> ConceptualMap:
    cmap = ConceptualMap()
    for i in range(3):
        cmap.add_place(f"p{i}", "room")
    return cmap


def test_room_category_is_a_distribution_over_the_knowledge_categories():
    belief = _room().room_category("room")
    assert tuple(belief) == load_knowledge().categories
    assert sum(belief.values()) == pytest.approx(1.0)


def test_kitchen_appearance_and_a_counter_make_a_room_a_kitchen():
    cmap = _room()
    prior = cmap.room_category("room")["kitchen"]
    cmap.observe_property("p0", "appearance", "kitchen_like")
    after_appearance = cmap.room_category("room")["kitchen"]
    cmap.observe_object("counter", "room")
    after_counter = cmap.room_category("room")
    assert prior < after_appearance < after_counter["kitchen"]
    assert max(after_counter, key=after_counter.get) == "kitchen"
    assert after_counter["kitchen"] > 0.9


def test_office_evidence_makes_an_office_and_elongated_places_a_corridor():
    office = _room()
    office.observe_object("desk", "room")
    office.observe_object("monitor", "room", on="object1")
    belief = office.room_category("room")
    assert max(belief, key=belief.get) == "office"
    corridor = _room()
    for i in range(3):
        corridor.observe_property(f"p{i}", "shape", "elongated")
    belief = corridor.room_category("room")
    assert max(belief, key=belief.get) == "corridor"


def test_newer_property_evidence_at_a_place_replaces_older():
    cmap = _room()
    cmap.observe_property("p0", "appearance", "bathroom_like")
    cmap.observe_property("p0", "appearance", "kitchen_like")
    fresh = _room()
    fresh.observe_property("p0", "appearance", "kitchen_like")
    assert cmap.room_category("room") == pytest.approx(fresh.room_category("room"))


def test_room_beliefs_reach_neighbours_through_phi_rc():
    cmap = _room()
    cmap.add_place("q0", "other")
    before = cmap.room_category("other")["kitchen"]
    cmap.connect_rooms("room", "other")
    cmap.observe_property("p0", "appearance", "kitchen_like")
    cmap.observe_object("counter", "room")
    assert cmap.room_category("other")["kitchen"] < before
    assert cmap.update().status is BPStatus.CONVERGED


def test_one_more_ignores_the_instances_already_found():
    """`another=True` (a task counting every instance) asks for one more: a found cup makes
    P(a cup in the room) 1, but P(another one) is the Poisson count still unseen there, which
    a search through the room lowers."""
    cmap = _room()
    cmap.observe_object("cup", "room")
    assert cmap.p_object_at("cup", "room") == 1.0
    assert list(cmap.p_object_at_per_category("cup", "room")) == [1.0] * len(
        cmap.knowledge.categories)
    before = cmap.p_object_at("cup", "room", another=True)
    assert 0.0 < before < 1.0
    cmap.observe_search("cup", "room", 0.9, 1.0)
    assert cmap.p_object_at("cup", "room", another=True) < before
    assert cmap.p_object_at("cup", "room") == 1.0
