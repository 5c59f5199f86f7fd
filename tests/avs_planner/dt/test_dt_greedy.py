"""The greedy rule's closed-form lookahead equals brute-force enumeration of observations."""

import itertools

import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    DTProblem,
    DTRewards,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import REJECT, START, confirm, look, move
from avs_planner.dt.greedy import greedy_action, repeated_look_cost, stop_choice


@pytest.fixture
def problem():
    cones = (ViewCone("a", (1, 0, 0), 0.35), ViewCone("b", (4, 0, 0), 0.25))
    return DTProblem(cones, TravelCosts.from_lists([3, 8], [[0, 6], [6, 0]]),
                     sensing_cost=1.5, rewards=DTRewards(120.0, 90.0))


def _brute_force(problem, cone, looks):
    start = TargetBelief.initial(problem).after(move(cone), NOTHING, problem.detector)
    total = problem.travel_cost(START, cone) + looks * problem.sensing_cost
    for outcomes in itertools.product([DETECTED, NOT_DETECTED], repeat=looks):
        belief, probability = start, 1.0
        for obs in outcomes:
            p_hit = belief.p_detect(cone, problem.detector)
            probability *= p_hit if obs == DETECTED else 1.0 - p_hit
            belief = belief.after(look(cone), obs, problem.detector)
        total += probability * stop_choice(problem, belief.robot, belief.detected,
                                           belief.probs)[0]
    return total


@pytest.mark.parametrize("looks", [1, 2, 3, 4])
@pytest.mark.parametrize("cone", [0, 1])
def test_repeated_look_cost_matches_enumeration(problem, cone, looks):
    closed = repeated_look_cost(problem, START, cone, problem.prior, looks)
    assert closed == pytest.approx(_brute_force(problem, cone, looks))


def test_greedy_goes_for_probability_per_cost_and_stops_when_hopeless(problem):
    assert greedy_action(problem, START, False, problem.prior) == move(0)
    hopeless = (0.001, 0.001, 0.998)
    assert greedy_action(problem, 0, False, hopeless) == REJECT


def test_greedy_confirms_a_convincing_detection(problem):
    assert greedy_action(problem, 0, True, (0.999, 0.0005, 0.0005)) == confirm(0)
    assert greedy_action(problem, 0, True, (0.999, 0.0005, 0.0005), steps_left=0) == confirm(0)
