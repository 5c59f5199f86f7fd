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
from avs_planner.dt.multi.lookahead import (
    any_mode_penalty,
    best_route,
    label_outlook,
    stop_decision,
)

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


def _route_by_enumeration(problem, route):
    """Expected cost of following `route` from START: enumerate where every label is and
    every detection the route reacts to."""
    locations = [*range(problem.n), NOWHERE]
    total = 0.0
    for targets in product(locations, repeat=problem.k):
        prior = 1.0
        for i, t in enumerate(targets):
            prior *= problem.single(i).prior[t if t != NOWHERE else problem.n]
        if prior > 0.0:
            total += prior * _follow(problem, route, targets, 0, START, [True] * problem.k)
    return total


def _follow(problem, route, targets, step, here, open_):
    """Expected cost from look `step` on, with the labels in `open_` still open."""
    if step == len(route.cones):  # reject what is left
        return sum(problem.single(i).rewards.miss_penalty
                   for i in range(problem.k) if open_[i] and targets[i] != NOWHERE)
    cone = route.cones[step]
    cost = problem.travel_cost(here, cone) + problem.sensing_cost
    reacting = [i for i in route.confirms[step] if open_[i]]
    expected = 0.0
    for seen in product([True, False], repeat=len(reacting)):
        p, after, penalty = 1.0, list(open_), 0.0
        for i, hit in zip(reacting, seen, strict=True):
            rate = problem.single(i).detector.p_detect(targets[i] == cone)
            p *= rate if hit else 1.0 - rate
            if hit and (problem.mode.value == "all" or all(after)):
                after[i] = False
                if targets[i] != cone:
                    penalty += problem.single(i).rewards.false_confirm_penalty
        if p == 0.0:
            continue
        over = not any(after) if problem.mode.value == "all" else not all(after)
        rest = 0.0 if over else _follow(problem, route, targets, step + 1, cone, after)
        expected += p * (penalty + rest)
    return cost + expected


@pytest.mark.parametrize("mode", ["all", "any"])
@pytest.mark.parametrize("first", [0, 1, 2])
def test_route_cost_equals_enumerating_the_route(mode, first):
    problem = _problem(mode, sensing=0.5)
    route = best_route(problem, MultiLabelBelief.initial(problem), (0, 1), first, 8, 4)
    assert route.cones[0] == first and len(route.cones) >= 2
    assert any(route.confirms)
    assert route.cost == pytest.approx(_route_by_enumeration(problem, route))


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
