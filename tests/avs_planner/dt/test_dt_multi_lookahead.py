"""The multi-label lookahead: its closed-form plan costs equal brute-force enumeration, and
its decisions do what a shared look is for."""

from itertools import product

import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    ActionKind,
    DetectorModel,
    DTRewards,
    LabelTarget,
    MultiLabelProblem,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.domain import NOWHERE, START
from avs_planner.dt.greedy import looks_then_stop_cost
from avs_planner.dt.multi import MultiLabelBelief, MultiLookaheadPolicy
from avs_planner.dt.multi.domain import MultiObservation, confirm_label, look_at, move_to
from avs_planner.dt.multi.lookahead import any_mode_penalty, label_outlook, stop_decision
from avs_planner.dt.multi.route import best_route

CONES = (ViewCone("a", (1, 0, 0), 0.0), ViewCone("b", (3, 0, 0), 0.0),
         ViewCone("c", (0, 3, 0), 0.0))


def _problem(mode="all", cup=(0.5, 0.2, 0.1), book=(0.0, 0.3, 0.5), sensing=2.0):
    return MultiLabelProblem(
        CONES,
        (LabelTarget("cup", cup, DetectorModel(0.2, 0.05), DTRewards(100.0, 80.0)),
         LabelTarget("book", book, DetectorModel(0.1, 0.1), DTRewards(60.0, 120.0))),
        TravelCosts.from_poses((0, 0, 0), CONES), sensing, mode)


@pytest.mark.parametrize("looks", [1, 2, 3])
@pytest.mark.parametrize("p", [0.05, 0.3, 0.8])
def test_label_outlook_splits_the_single_label_lookahead(looks, p):
    single = _problem().single(0)
    p_confirm, confirm, reject = label_outlook(single, p, 0.3, looks)
    expected = looks_then_stop_cost(single, p, 0.3, looks) - looks * single.sensing_cost
    assert confirm + reject == pytest.approx(expected)
    assert 0.0 <= p_confirm <= 1.0


def test_any_mode_penalty_equals_enumerating_which_labels_confirm():
    outlooks = [(0.3, 6.0, 20.0), (0.5, 25.0, 10.0), (0.0, 0.0, 7.0), (0.2, 1.0, 30.0)]
    expected = 0.0
    for fires in product([True, False], repeat=len(outlooks)):
        p, conditional = 1.0, []
        for (q, confirm, reject), fire in zip(outlooks, fires, strict=True):
            p *= q if fire else 1.0 - q
            if p > 0.0:
                conditional.append(confirm / q if fire else reject / (1.0 - q))
        if p == 0.0:
            continue
        confirming = [c for c, fire in zip(conditional, fires, strict=True) if fire]
        expected += p * (min(confirming) if confirming else sum(conditional))
    assert any_mode_penalty(outlooks) == pytest.approx(expected)


def _route_by_enumeration(problem, route, open_labels=(0, 1)):
    """Expected cost of following `route` from START for `open_labels`: enumerate where
    every label is and every detection the route reacts to."""
    locations = [*range(problem.n), NOWHERE]
    total = 0.0
    for targets in product(locations, repeat=problem.k):
        prior = 1.0
        for i, t in enumerate(targets):
            prior *= problem.single(i).prior[t if t != NOWHERE else problem.n]
        if prior > 0.0:
            state = {"open": [i in open_labels for i in range(problem.k)], "ended": False,
                     "labels": open_labels}
            total += prior * _follow(problem, route, targets, 0, START, state)
    return total


def _follow(problem, route, targets, step, here, state):
    """Expected cost from look `step` on; `state`: which labels are open, search ended?"""
    all_mode = problem.mode.value == "all"
    going = any(state["open"]) and not state["ended"]
    if step == len(route.cones) or not going:  # reject what is left
        return sum(problem.single(i).rewards.miss_penalty for i in range(problem.k)
                   if going and state["open"][i] and targets[i] != NOWHERE)
    cone = route.cones[step]
    return (problem.travel_cost(here, cone) + problem.sensing_cost
            + _resolve(problem, route, targets, step, cone, state, 0, all_mode))


def _resolve(problem, route, targets, step, cone, state, i, all_mode):
    """Expected cost of label i's (and the later labels') reactions to look `step`, then the
    rest of the route."""
    if i == problem.k or state["ended"]:
        return _follow(problem, route, targets, step + 1, cone, state)
    if not state["open"][i]:
        return _resolve(problem, route, targets, step, cone, state, i + 1, all_mode)
    single = problem.single(i)
    rate = single.detector.p_detect(targets[i] == cone)
    action = route.on_detection[step][state["labels"].index(i)]
    wrong = single.rewards.false_confirm_penalty if targets[i] != cone else 0.0
    missed = single.rewards.miss_penalty if targets[i] != NOWHERE else 0.0
    closed = {**state, "open": [o and j != i for j, o in enumerate(state["open"])]}
    confirmed = {**closed, "ended": not all_mode}
    on_miss = _resolve(problem, route, targets, step, cone, state, i + 1, all_mode)
    if action == "confirm":
        on_hit = wrong + _resolve(problem, route, targets, step, cone, confirmed, i + 1, all_mode)
    elif action == "reject":
        on_hit = missed + _resolve(problem, route, targets, step, cone, closed, i + 1, all_mode)
    elif action == "ignore":
        on_hit = on_miss
    else:  # verify: one more look here, confirm on a second hit
        on_hit = problem.sensing_cost + rate * (
            wrong + _resolve(problem, route, targets, step, cone, confirmed, i + 1, all_mode)
        ) + (1.0 - rate) * on_miss
    return rate * on_hit + (1.0 - rate) * on_miss


@pytest.mark.parametrize("mode", ["all", "any"])
@pytest.mark.parametrize("first", [0, 1, 2])
@pytest.mark.parametrize("sensing", [0.5, 20.0])  # cheap looks verify, dear ones stop
@pytest.mark.parametrize("settle", [True, False])
def test_route_cost_equals_enumerating_the_route(mode, first, sensing, settle):
    problem = _problem(mode, sensing=sensing)
    route = best_route(problem, MultiLabelBelief.initial(problem), (0, 1), first, 12, 4, settle)
    assert route.cones[0] == first and len(route.cones) >= 2
    assert route.cost == pytest.approx(_route_by_enumeration(problem, route))


def test_routes_settle_detections_every_way_or_confirm_and_ignore():
    problem = _problem("any", sensing=20.0)
    start = MultiLabelBelief.initial(problem)
    route = best_route(problem, start, (0, 1), 0, 12, 4)
    assert {a for look in route.on_detection for a in look} == {"confirm", "reject", "verify"}
    route = best_route(problem, start, (0, 1), 0, 12, 4, settle=False)
    assert {a for look in route.on_detection for a in look} == {"confirm", "ignore"}


def test_routes_verify_an_unconvincing_detection():
    # a label spread thinly: one detection leaves it doubtful, a second settles it
    problem = _problem("all", cup=(0.2, 0.2, 0.2), book=(0.0, 0.0, 0.0), sensing=0.5)
    route = best_route(problem, MultiLabelBelief.initial(problem), (0,), 0, 8, 4)
    assert route.on_detection[0] == ("verify",)
    assert route.cost == pytest.approx(_route_by_enumeration(problem, route, (0,)))


def test_first_look_goes_where_both_labels_may_be():
    # cup is more likely in a, but c holds most of both labels' mass together
    problem = _problem(cup=(0.45, 0.0, 0.4), book=(0.0, 0.0, 0.6))
    action = MultiLookaheadPolicy(problem).decide(MultiLabelBelief.initial(problem), 8)
    assert action == move_to(2) and action.label in ("cup", "book")


def test_a_convincing_detection_is_confirmed_and_names_its_label():
    problem = _problem()
    belief = MultiLabelBelief.initial(problem).after(move_to(2), None, problem)
    for _ in range(2):  # two hits for the book at c, none for the cup
        belief = belief.after(look_at(2), MultiObservation(_obs(False, True)), problem)
    action = MultiLookaheadPolicy(problem).decide(belief, 6)
    assert action == confirm_label("book", 2) and action.label == "book"


def _obs(cup, book):
    return (DETECTED if cup else NOT_DETECTED, DETECTED if book else NOT_DETECTED)


def test_nothing_to_find_rejects_without_moving():
    problem = _problem(cup=(0.0, 0.0, 0.0), book=(0.0, 0.0, 0.0))
    belief = MultiLabelBelief.initial(problem)
    action = MultiLookaheadPolicy(problem).decide(belief, 8)
    assert action.kind is ActionKind.REJECT
    assert stop_decision(problem, belief)[0] == 0.0


def test_no_steps_left_forces_the_cheapest_stop_per_mode():
    for mode, expected in [("all", ActionKind.REJECT), ("any", ActionKind.CONFIRM)]:
        problem = _problem(mode)
        belief = MultiLabelBelief.initial(problem).after(move_to(2), None, problem)
        belief = belief.after(look_at(2), MultiObservation(_obs(False, True)), problem)
        # all: the cup (not seen) is closed first; any: the book's confirm ends the search
        action = MultiLookaheadPolicy(problem).decide(belief, 0)
        assert action.kind is expected
