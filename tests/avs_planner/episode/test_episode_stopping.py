"""The building-level stopping rule (`strategies/switching/stopping.py`) on the office
corridor's map."""

from __future__ import annotations

import math

import numpy as np
import pytest

from avs_planner.body import JointRange, RobotBody
from avs_planner.strategies.switching.stopping import Option, Remaining, look_cost, remaining
from conceptual_map.conceptual.existence import ObjectLedger
from conceptual_map.conceptual.placeholders import PlaceholderEvidence, p_label_beyond
from conceptual_map.knowledge import load_knowledge


def test_unsearched_rooms_and_placeholders_keep_the_search_going(corridor) -> None:  # noqa: ANN001
    """After one look around the corridor: doors and frontiers may lead to a kitchen, so the
    cereal box may well be in the building and exploring is worth its cost."""
    mind, builder, executor = corridor
    belief = remaining(mind, builder, executor.robot.pose[:2])
    kinds = {o.kind for o in belief.options}
    assert kinds == {"room", "placeholder"}
    assert 0.3 < belief.p < 1.0
    assert belief.worth_going_on(500.0)
    best = belief.best(500.0)
    assert best is not None and best.kind == "placeholder" and best.p > 0.1


def test_a_building_searched_through_gives_up_naming_what_is_left(corridor) -> None:  # noqa: ANN001
    """Every placeholder explored and every room looked through: the probability left is
    small, no continuation is worth its cost, and the reason says how much is left."""
    mind, builder, executor = corridor
    for pid in mind.place_map.placeholders:
        mind.tried_placeholders[pid] = builder.config.max_placeholder_tries
    for rid in mind.place_map.rooms:
        for label in builder.labels:
            mind.cmap.observe_search(label, rid, coverage=1.0, p_detect=0.95)
        for space in mind.cmap.objects.sublocations(rid, builder.task.target):
            mind.cmap.observe_search(builder.task.target, space, coverage=1.0, p_detect=0.95)
    belief = remaining(mind, builder, executor.robot.pose[:2], look=10.0)
    assert {o.kind for o in belief.options} == {"room"}
    assert all(o.cost >= 10.0 for o in belief.options)  # a look at least, even standing there
    assert belief.p < 0.1
    assert not belief.worth_going_on(500.0)
    text = belief.describe(500.0)
    assert "P(target in space not yet searched)" in text
    assert "no continuation is worth its cost" in text
    # a much larger reward makes the same small chance worth a look again
    assert belief.worth_going_on(1e6)


def _known_rate(options: tuple[Option, ...]) -> Remaining:
    """The belief over `options` under a known building rate (Poisson: mass -ln(1 - p))."""
    return Remaining.of(options, lambda p: -math.log1p(-p), lambda m: -math.expm1(-m))


def test_the_rule_weighs_what_lies_within_each_cost() -> None:
    """Ten placeholders of p = 0.09 are worth exploring although none alone is: any set of
    options costs at least its dearest one's bound, and R x P of all ten (0.61) is more
    than 53. A near room of p = 0.004 does not make the far rooms' 0.05 worth 60."""
    spread = tuple(Option("placeholder", f"placeholder{k}", 0.09, 53.0) for k in range(10))
    assert all(o.value(500.0) < 0 for o in spread)
    belief = _known_rate(spread)
    assert belief.p == pytest.approx(1.0 - (1.0 - 0.09) ** 10)
    assert belief.worth_going_on(500.0)
    near_and_far = (Option("room", "room1", 0.004, 10.0), Option("room", "room2", 0.02, 60.0),
                    Option("placeholder", "placeholder1", 0.03, 60.0))
    belief = _known_rate(near_and_far)
    assert 500.0 * belief.p > belief.cheapest().cost  # the cheapest step alone would go on
    assert not belief.worth_going_on(500.0)  # 500 x 0.054 = 27 < 60, 500 x 0.004 = 2 < 10
    assert belief.cheapest().name == "room1" and "room room1" in belief.describe(500.0)
    assert belief.worth_going_on(1200.0)  # 1200 x 0.054 = 64 > 60
    # much left far away is worth the way there
    assert _known_rate((*near_and_far, Option("placeholder", "p9", 0.2, 80.0))) \
        .worth_going_on(500.0)
    assert not Remaining.of((), float, float).worth_going_on(500.0)
    assert "nothing is left" in Remaining.of((), float, float).describe(500.0)


def test_p_beyond_a_placeholder_follows_its_hypotheses() -> None:
    """No open space and no door: nothing behind it. A door: at least one new room, whose
    chance to hold a cereal box is its category posterior against the fresh-room lambda."""
    knowledge = load_knowledge()
    ledger = ObjectLedger(knowledge)
    lam = ledger.fresh_room_lambda("cerealbox")
    marginal = np.full(len(knowledge.categories), 1.0 / len(knowledge.categories))
    closed = p_label_beyond(knowledge, marginal, PlaceholderEvidence("r", 0.0, 0.0), lam)
    door = p_label_beyond(knowledge, marginal, PlaceholderEvidence("r", 0.0, 1.0), lam)
    assert closed == pytest.approx(0.0)
    assert 0.0 < door < 1.0
    # more rooms cannot make it less likely; a label no room holds is never behind it
    zero = p_label_beyond(knowledge, marginal, PlaceholderEvidence("r", 0.0, 1.0), lam * 0.0)
    assert zero == pytest.approx(0.0)
    ledger.record_search("cerealbox", "r", coverage=1.0, p_detect=1.0)  # not a fresh room
    assert np.all(ledger.fresh_room_lambda("cerealbox") == lam)


def test_a_look_around_costs_a_full_turn_and_a_frame_per_heading() -> None:
    body = RobotBody(
        name="pioneer", footprint_radius=0.25, holonomic=False, camera_height=1.4,
        torso=JointRange(0.0, 0.0), pan=JointRange(-2.77, 2.77), tilt=JointRange(-0.82, 0.54),
        hfov=1.05, vfov=0.8, depth_range=5.0, detect_range=4.0, laser_range=5.6,
        linear_speed=0.5, angular_speed=1.0, torso_speed=1.0, pan_speed=1.0, tilt_speed=1.0,
        scan_time=0.1, sensing_time=0.5)
    assert look_cost(None, 6) == 0.0
    assert look_cost(body, 6) == pytest.approx(2.0 * math.pi + 6 * 0.5)
    assert look_cost(body, 1) == pytest.approx(2.0 * math.pi + 2 * 0.5)  # at least two


def test_the_building_belief_adds_the_spaces_expected_counts(corridor) -> None:  # noqa: ANN001
    """The options' spaces are disjoint and share the building's rate: P is that of their
    summed expected counts, below the independent 1 - prod(1 - p) once looks have lowered the
    rate (a room searched in vain makes every other less likely too)."""
    mind, builder, executor = corridor
    cmap, label = mind.cmap, builder.task.target
    for rid in mind.place_map.rooms:
        cmap.observe_search(label, rid, coverage=0.9, p_detect=0.9)
    belief = remaining(mind, builder, executor.robot.pose[:2])
    masses = sum(float(cmap.mass(label, o.p)) for o in belief.options)
    assert belief.p == pytest.approx(float(cmap.p_any(label, masses)))
    assert cmap.rate_posterior(label).beta > cmap.knowledge.rate_shape  # the looks count
    assert belief.p < 1.0 - math.prod(1.0 - o.p for o in belief.options)
