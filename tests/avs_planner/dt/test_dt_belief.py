"""Belief updates equal hand-computed Bayes updates, in our belief and in pomdp-py's histogram."""

import random

import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    DetectorModel,
    DTProblem,
    DtSessionError,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.agent import ViewConeAgent
from avs_planner.dt.belief import TargetBelief, histogram_probs
from avs_planner.dt.domain import look, move


@pytest.fixture
def problem():
    cones = (ViewCone("a", (1, 0, 0), 0.5), ViewCone("b", (2, 0, 0), 0.3))
    return DTProblem(cones, TravelCosts.from_lists([1, 2], [[0, 1], [1, 0]]),
                     DetectorModel(false_negative=0.2, false_positive=0.05))


def test_miss_lowers_the_looked_cone_by_bayes(problem):
    belief = TargetBelief.initial(problem).after(move(0), NOTHING, problem.detector)
    belief = belief.after(look(0), NOT_DETECTED, problem.detector)
    # P(miss | in a) = 0.2, P(miss | elsewhere) = 0.95
    total = 0.5 * 0.2 + 0.3 * 0.95 + 0.2 * 0.95
    assert belief.probs == pytest.approx((0.1 / total, 0.285 / total, 0.19 / total))
    assert belief.misses == (1, 0) and not belief.detected


def test_hit_then_miss_matches_hand_computation(problem):
    b = TargetBelief.initial(problem).after(move(1), NOTHING, problem.detector)
    b = b.after(look(1), DETECTED, problem.detector)
    # P(hit | in b) = 0.8, P(hit | elsewhere) = 0.05
    w = [0.5 * 0.05, 0.3 * 0.8, 0.2 * 0.05]
    assert b.probs == pytest.approx(tuple(x / sum(w) for x in w))
    assert b.detected
    b = b.after(look(1), NOT_DETECTED, problem.detector)
    w = [w[0] * 0.95, w[1] * 0.2, w[2] * 0.95]
    assert b.probs == pytest.approx(tuple(x / sum(w) for x in w))
    assert b.hits == (0, 1) and b.misses == (0, 1)


def test_pomdp_py_histogram_update_agrees(problem):
    agent = ViewConeAgent(problem, random.Random(0))
    belief = TargetBelief.initial(problem)
    for action, obs in [(move(0), NOTHING), (look(0), DETECTED), (look(0), NOT_DETECTED),
                        (move(1), NOTHING), (look(1), NOT_DETECTED)]:
        agent.update(action, obs)
        belief = belief.after(action, obs, problem.detector)
        assert histogram_probs(agent.belief, problem.n) == pytest.approx(belief.probs)
    assert all(s.robot == 1 for s in agent.belief)


def test_impossible_observation_is_an_error():
    cones = (ViewCone("a", (1, 0, 0), 0.0),)
    problem = DTProblem(cones, TravelCosts.from_lists([1], [[0]]),
                        DetectorModel(false_negative=0.2, false_positive=0.0))
    belief = TargetBelief.initial(problem).after(move(0), NOTHING, problem.detector)
    with pytest.raises(DtSessionError, match="impossible"):
        belief.after(look(0), DETECTED, problem.detector)


def test_look_needs_a_detection_result(problem):
    belief = TargetBelief.initial(problem).after(move(0), NOTHING, problem.detector)
    with pytest.raises(DtSessionError, match="needs a detection result"):
        belief.after(look(0), NOTHING, problem.detector)
