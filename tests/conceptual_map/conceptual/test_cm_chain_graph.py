"""Chain graph: its pgmpy factors, exact checks of the facade's beliefs, structural events."""

import numpy as np
import pytest

from conceptual_map.conceptual import ConceptualError, ConceptualMap, category_variable
from conceptual_map.conceptual.exact import exact_marginals


def _building() -> ConceptualMap:
    """A corridor with three rooms off it (a tree), some evidence everywhere."""
    cmap = ConceptualMap()
    for room, places in {"corr": 4, "r1": 2, "r2": 2, "r3": 1}.items():
        for i in range(places):
            cmap.add_place(f"{room}_p{i}", room)
        if room != "corr":
            cmap.connect_rooms("corr", room)
    cmap.observe_property("corr_p0", "shape", "elongated")
    cmap.observe_property("corr_p1", "appearance", {"corridor_like": 0.7, "office_like": 0.3})
    cmap.observe_property("r1_p0", "appearance", "kitchen_like")
    cmap.observe_property("r2_p1", "size", "small")
    cmap.observe_object("desk", "r3")
    cmap.observe_room_property("corr", "size", "large")
    cmap.observe_room_property("r2", "shape", {"square": 0.6, "rectangular": 0.4})
    return cmap


def _assert_matches_exact(cmap: ConceptualMap, explicit: bool, atol: float) -> None:
    exact = exact_marginals(cmap.factors(explicit_properties=explicit))
    for room in cmap.graph.rooms:
        np.testing.assert_allclose(cmap.room_marginal(room), exact[category_variable(room)],
                                   atol=atol)


def test_tree_beliefs_equal_exact_inference_on_the_reduced_and_explicit_chain_graph():
    cmap = _building()
    _assert_matches_exact(cmap, explicit=False, atol=1e-6)
    _assert_matches_exact(cmap, explicit=True, atol=1e-6)


def test_loopy_building_is_close_to_exact():
    cmap = _building()
    cmap.connect_rooms("r1", "r2")
    cmap.connect_rooms("r2", "r3")
    _assert_matches_exact(cmap, explicit=False, atol=0.02)


def test_explicit_factors_hold_property_variables_and_evidence():
    factors = _building().factors(explicit_properties=True)
    scopes = [tuple(f.scope()) for f in factors]
    assert (category_variable("r1"), "appearance[r1_p0]") in scopes
    assert ("appearance[r1_p0]",) in scopes
    assert (category_variable("corr"), "size[room:corr]") in scopes


def test_events_rerun_inference_only_when_something_changed():
    cmap = _building()
    first = cmap.update()
    assert cmap.update() is first
    cmap.observe_property("r2_p0", "appearance", "bathroom_like")
    second = cmap.update()
    assert second is not first
    assert cmap.room_category("r2")["bathroom"] > 0.5


def test_moving_a_place_moves_its_evidence_to_the_new_room():
    cmap = _building()
    before = cmap.room_category("r2")["kitchen"]
    cmap.add_place("r1_p0", "r2")
    assert cmap.room_category("r2")["kitchen"] > before
    _assert_matches_exact(cmap, explicit=False, atol=1e-6)


def test_merge_rooms_keeps_places_links_and_objects():
    cmap = _building()
    cmap.merge_rooms("r2", "r3")
    assert "r3" not in cmap.graph.rooms
    assert cmap.graph.places_of("r2") == {"r2_p0", "r2_p1", "r3_p0"}
    assert cmap.graph.neighbours("r2") == {"corr"}
    assert cmap.objects.objects["object1"].room == "r2"
    assert cmap.p_object_at("desk", "r2") == 1.0
    _assert_matches_exact(cmap, explicit=False, atol=1e-6)


def test_moving_an_object_moves_it_with_what_stands_on_it_and_its_evidence():
    """A table seen through a door was credited to the corridor; once the room beyond is a
    room of its own, the table and the cereal box on it belong there."""
    cmap = _building()
    table = cmap.observe_object("table", "corr")
    box = cmap.observe_object("cerealbox", "corr", on=table)
    corridor_before = cmap.room_category("corr")["kitchen"]
    kitchen_before = cmap.room_category("r1")["kitchen"]
    cmap.move_object(table, "r1")
    records = cmap.objects.objects
    assert records[table].room == "r1" and records[box].room == "r1"
    assert records[box].support == table
    assert cmap.p_object_at("table", "r1") == 1.0
    assert cmap.room_category("r1")["kitchen"] > kitchen_before
    assert cmap.room_category("corr")["kitchen"] < corridor_before
    _assert_matches_exact(cmap, explicit=False, atol=1e-6)
    cmap.move_object(table, "r1")  # already there: nothing changes
    assert records[table].room == "r1"
    with pytest.raises(ConceptualError, match="moves with it"):
        cmap.move_object(box, "r2")
    with pytest.raises(ConceptualError, match="unknown object"):
        cmap.move_object("object99", "r2")


def test_remove_place_drops_its_evidence():
    cmap = _building()
    before = cmap.room_category("r1")["kitchen"]
    cmap.remove_place("r1_p0")
    assert cmap.room_category("r1")["kitchen"] < before
    assert "r1_p0" not in cmap.graph.places_of("r1")
    _assert_matches_exact(cmap, explicit=True, atol=1e-6)


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (lambda m: m.observe_property("nowhere", "size", "small"), "unknown place 'nowhere'"),
        (lambda m: m.observe_property("r1_p0", "smell", "coffee"), "unknown property kind"),
        (lambda m: m.observe_property("r1_p0", "size", "huge"), "unknown size value 'huge'"),
        (lambda m: m.observe_property("r1_p0", "size", {"small": -1.0}), "non-negative"),
        (lambda m: m.observe_property("r1_p0", "size", {"small": "lots"}), "needs numbers"),
        (lambda m: m.add_placeholder("ph", "r1", open_space_m2="big"), "must be a number"),
        (lambda m: m.connect_rooms("r1", "attic"), "unknown room 'attic'"),
        (lambda m: m.connect_rooms("r1", "r1"), "itself"),
        (lambda m: m.room_category("attic"), "unknown room 'attic'"),
        (lambda m: m.merge_rooms("r1", "r1"), "itself"),
        (lambda m: m.add_place("", "r1"), "non-empty"),
    ],
)
def test_bad_events_raise_clear_errors(action, message):
    with pytest.raises(ConceptualError, match=message):
        action(_building())


def test_merged_factors_give_the_same_exact_marginals():
    cmap = _building()
    reduced = exact_marginals(cmap.factors())
    merged = exact_marginals(cmap.factors(merged=True))
    assert len(cmap.factors(merged=True)) == len(cmap.graph.rooms) + 3
    for variable, values in reduced.items():
        np.testing.assert_allclose(merged[variable], values, atol=1e-10)


@pytest.mark.parametrize("seed", range(4))
def test_random_event_sequences_keep_tree_beliefs_exact(seed):
    """Random adds, moves, observations and merges on a tree of rooms, checked after each batch."""
    rng = np.random.default_rng(seed)
    cmap = ConceptualMap()
    knowledge = cmap.knowledge
    cmap.add_place("p0", "room0")
    for step in range(1, 40):
        rooms = cmap.graph.rooms
        action = rng.integers(4)
        if action == 0 and len(rooms) < 8:
            parent = rooms[int(rng.integers(len(rooms)))]
            cmap.add_place(f"p{step}", f"room{step}")
            cmap.connect_rooms(parent, f"room{step}")
        elif action == 1:
            cmap.add_place(f"p{step}", rooms[int(rng.integers(len(rooms)))])
        elif action == 2:
            places = sorted(p for r in rooms for p in cmap.graph.places_of(r))
            kind = str(rng.choice(list(knowledge.properties)))
            value = str(rng.choice(knowledge.properties[kind].values))
            cmap.observe_property(places[int(rng.integers(len(places)))], kind, value)
        elif len(rooms) > 2:
            # merging two adjacent rooms keeps the room graph a tree
            keep = rooms[int(rng.integers(len(rooms)))]
            neighbours = sorted(cmap.graph.neighbours(keep))
            if neighbours:
                cmap.merge_rooms(keep, neighbours[0])
        if step % 10 == 0:
            _assert_matches_exact(cmap, explicit=False, atol=1e-6)
    _assert_matches_exact(cmap, explicit=False, atol=1e-6)


def test_property_evidence_is_pgmpy_s_reduced_factor_to_the_last_bit():
    """The chain graph reduces P(value | category) by the evidence with numpy (pgmpy is not
    imported by an episode); the values are pgmpy's product and marginalisation exactly,
    for every property of the default knowledge, hard and soft evidence."""
    from pgmpy.factors.discrete import DiscreteFactor

    from conceptual_map.conceptual.chain_graph import _reduced_likelihood
    from conceptual_map.knowledge import load_knowledge

    rng = np.random.default_rng(7)
    for kind, model in load_knowledge().properties.items():
        n = model.table.shape[1]
        evidence = [np.eye(n)[i] for i in range(n)]
        evidence += [rng.random(n) * 10.0 ** rng.integers(-6, 4) for _ in range(200)]
        for weights in evidence:
            cpd = DiscreteFactor(["category", kind], list(model.table.shape), model.table)
            reduced = cpd.product(DiscreteFactor([kind], [n], weights), inplace=False)
            expected = reduced.marginalize([kind], inplace=False).values
            assert np.array_equal(_reduced_likelihood(model.table, weights), expected), kind
