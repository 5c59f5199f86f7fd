"""Placeholders: hypothesis weights, exact hypothetical-room posteriors, phi_rc influence."""

import math

import numpy as np
import pytest
from pgmpy.factors.discrete import DiscreteFactor

from conceptual_map.conceptual import (
    NO_NEW_ROOM,
    ConceptualError,
    ConceptualMap,
    Hypothesis,
    PlaceholderEvidence,
    category_variable,
    hypothesis_weights,
)
from conceptual_map.conceptual.exact import exact_marginals
from conceptual_map.knowledge import load_knowledge


def _corridor_with_placeholder(open_space: float = 12.0, p_door: float = 0.6) -> ConceptualMap:
    cmap = ConceptualMap()
    for i in range(3):
        cmap.add_place(f"c{i}", "corr")
        cmap.observe_property(f"c{i}", "shape", "elongated")
    cmap.add_placeholder("ph", "corr", open_space_m2=open_space, p_door=p_door)
    return cmap


@pytest.mark.parametrize(("space", "door"), [(0.0, 0.0), (3.0, 0.2), (30.0, 0.9), (0.5, 1.0)])
def test_weights_are_a_distribution_over_the_six_hypotheses(space, door):
    evidence = PlaceholderEvidence("r", space, door)
    weights = hypothesis_weights(load_knowledge().placeholder, evidence)
    assert set(weights) == set(Hypothesis)
    assert sum(weights.values()) == pytest.approx(1.0)
    assert min(weights.values()) >= 0.0


def test_weights_follow_open_space_and_doors():
    model = load_knowledge().placeholder
    nothing = hypothesis_weights(model, PlaceholderEvidence("r", 0.0, 0.0))
    assert nothing[Hypothesis.NO_NEW_PLACES] == pytest.approx(1.0)
    small = hypothesis_weights(model, PlaceholderEvidence("r", 2.0, 0.0))
    large = hypothesis_weights(model, PlaceholderEvidence("r", 30.0, 0.0))
    assert large[Hypothesis.NO_NEW_PLACES] < small[Hypothesis.NO_NEW_PLACES]
    assert large[Hypothesis.PLACES_THEN_ROOM] > small[Hypothesis.PLACES_THEN_ROOM]
    door = hypothesis_weights(model, PlaceholderEvidence("r", 2.0, 1.0))
    assert door[Hypothesis.ROOM_DIRECTLY] + door[Hypothesis.ROOM_THEN_ROOM] == pytest.approx(1.0)


def test_hypothetical_room_posteriors_equal_exact_inference_with_the_rooms_added():
    cmap = _corridor_with_placeholder()
    cmap.add_place("k0", "kitchen1")
    cmap.connect_rooms("corr", "kitchen1")
    cmap.observe_property("k0", "appearance", "kitchen_like")
    knowledge, states = cmap.knowledge, len(cmap.knowledge.categories)
    phi = knowledge.connectivity
    extra = [DiscreteFactor(["n1"], [states], knowledge.prior),
             DiscreteFactor(["n2"], [states], knowledge.prior),
             DiscreteFactor([category_variable("corr"), "n1"], [states, states], phi),
             DiscreteFactor(["n1", "n2"], [states, states], phi)]
    exact = exact_marginals(cmap.factors() + extra)
    two_room_any = _exact_any(cmap.factors() + extra, states)
    prediction = cmap.placeholder_prediction("ph")
    weights = prediction.weights
    one = weights[Hypothesis.PLACES_THEN_ROOM] + weights[Hypothesis.ROOM_DIRECTLY]
    two = weights[Hypothesis.PLACES_THEN_TWO_ROOMS] + weights[Hypothesis.ROOM_THEN_ROOM]
    single = exact_marginals(cmap.factors() + extra[:1] + extra[2:3])["n1"]
    expected_first = one * single + two * exact["n1"]
    expected_any = one * single + two * two_room_any
    names = knowledge.categories
    np.testing.assert_allclose([prediction.first_room[c] for c in names], expected_first,
                               atol=1e-6)
    np.testing.assert_allclose([prediction.any_room[c] for c in names], expected_any, atol=1e-6)
    assert sum(prediction.first_room.values()) + prediction.no_new_room == pytest.approx(1.0)


def _exact_any(factors: list[DiscreteFactor], states: int) -> np.ndarray:
    """P(n1 = c or n2 = c) from the exact joint of the two hypothetical rooms."""
    from pgmpy.inference import VariableElimination

    from conceptual_map.conceptual.exact import markov_network

    joint = VariableElimination(markov_network(factors)).query(
        ["n1", "n2"], show_progress=False)
    table = joint.values if joint.variables == ["n1", "n2"] else joint.values.T
    table = table / table.sum()
    return table.sum(axis=1) + table.sum(axis=0) - np.diag(table)


def _room_with_placeholder() -> ConceptualMap:
    """An uncategorised room with a placeholder at a likely doorway, and a neighbour room."""
    cmap = ConceptualMap()
    cmap.add_place("r0", "room")
    cmap.add_placeholder("ph", "room", open_space_m2=12.0, p_door=0.6)
    cmap.add_place("x0", "next")
    cmap.connect_rooms("room", "next")
    return cmap


def _make_kitchen(cmap: ConceptualMap, place: str, room: str) -> None:
    cmap.observe_property(place, "appearance", "kitchen_like")
    cmap.observe_object("counter", room)
    cmap.observe_object("fridge", room)


def test_a_detected_kitchen_at_the_placeholder_changes_its_prediction_via_phi_rc():
    plain, kitchen = _room_with_placeholder(), _room_with_placeholder()
    _make_kitchen(kitchen, "r0", "room")
    assert kitchen.room_category("room")["kitchen"] > 0.9
    before, after = plain.placeholder_category("ph"), kitchen.placeholder_category("ph")
    # phi_rc(kitchen, kitchen) is low and phi_rc(kitchen, living_room) high in the knowledge.
    assert after["kitchen"] < before["kitchen"] - 0.02
    assert after["living_room"] > before["living_room"] + 0.02
    assert after[NO_NEW_ROOM] == pytest.approx(before[NO_NEW_ROOM])


def test_a_detected_kitchen_next_door_changes_the_prediction_through_the_rooms_belief():
    plain, kitchen = _room_with_placeholder(), _room_with_placeholder()
    _make_kitchen(kitchen, "x0", "next")
    assert kitchen.room_category("room")["kitchen"] < plain.room_category("room")["kitchen"]
    before, after = plain.placeholder_category("ph"), kitchen.placeholder_category("ph")
    assert after["kitchen"] > before["kitchen"]
    assert not math.isclose(after["kitchen"], before["kitchen"], abs_tol=1e-3)


def test_placeholder_in_a_kitchen_predicts_fewer_kitchens_than_one_in_a_corridor():
    in_corridor = _corridor_with_placeholder()
    in_kitchen = ConceptualMap()
    in_kitchen.add_place("k0", "kitchen1")
    in_kitchen.observe_property("k0", "appearance", "kitchen_like")
    in_kitchen.observe_object("counter", "kitchen1")
    in_kitchen.add_placeholder("ph", "kitchen1", open_space_m2=12.0, p_door=0.6)
    # phi_rc(kitchen, kitchen) is low in the default knowledge: kitchens rarely adjoin kitchens.
    assert in_kitchen.placeholder_category("ph")["kitchen"] < \
        in_corridor.placeholder_category("ph")["kitchen"]


def test_placeholder_events_and_errors():
    cmap = _corridor_with_placeholder(open_space=0.0, p_door=0.0)
    assert cmap.placeholder_category("ph")[NO_NEW_ROOM] == pytest.approx(1.0)
    cmap.update_placeholder("ph", open_space_m2=20.0)
    assert cmap.placeholder_category("ph")[NO_NEW_ROOM] < 0.5
    cmap.add_place("o0", "office1")
    cmap.add_placeholder("ph2", "office1")
    cmap.merge_rooms("corr", "office1")
    assert cmap.placeholders["ph2"].room == "corr"
    cmap.remove_placeholder("ph")
    with pytest.raises(ConceptualError, match="unknown placeholder 'ph'"):
        cmap.placeholder_category("ph")
    with pytest.raises(ConceptualError, match="p_door"):
        cmap.update_placeholder("ph2", p_door=1.5)
    with pytest.raises(ConceptualError, match="unknown room"):
        cmap.add_placeholder("ph3", "attic")
