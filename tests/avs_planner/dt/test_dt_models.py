"""pomdp-py models: distributions sum to one, observations read the state, rewards are costs."""

import random

import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    REJECT,
    DetectorModel,
    DTProblem,
    DTRewards,
    DTState,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.domain import NOWHERE, START, confirm, look, move
from avs_planner.dt.models import (
    ViewConeObservationModel,
    ViewConePolicyModel,
    ViewConeRewardModel,
    ViewConeTransitionModel,
    valid_actions,
)


@pytest.fixture
def problem():
    cones = (ViewCone("a", (1, 0, 0), 0.4), ViewCone("b", (2, 0, 0), 0.0),
             ViewCone("c", (3, 0, 0), 0.4))
    return DTProblem(cones, TravelCosts.from_lists([1, 2, 3], [[0, 1, 2], [1, 0, 1], [2, 1, 0]]),
                     DetectorModel(0.2, 0.05), 1.5, DTRewards(50.0, 70.0))


def test_transition_distributions_sum_to_one(problem):
    model = ViewConeTransitionModel(problem, random.Random(0))
    for state in model.get_all_states():
        for action in [move(0), look(0), confirm(0), REJECT]:
            assert sum(p for _, p in model.successors(state, action)) == pytest.approx(1.0)


def test_look_samples_detections_at_detector_rates(problem):
    model = ViewConeTransitionModel(problem, random.Random(1))
    state = DTState(0, 0)
    hits = sum(model.sample(state, look(0)).detected for _ in range(4000))
    assert hits / 4000 == pytest.approx(0.8, abs=0.03)
    assert model.probability(DTState(0, 2, True), DTState(0, 2), look(0)) == pytest.approx(0.05)


def test_observation_reads_the_detection_flag(problem):
    model = ViewConeObservationModel()
    assert model.sample(DTState(0, 0, True), look(0)) == DETECTED
    assert model.sample(DTState(0, 0, False), look(0)) == NOT_DETECTED
    assert model.sample(DTState(0, 0, True), move(0)) == NOTHING
    assert model.probability(DETECTED, DTState(0, 0, False), look(0)) == 0.0


def test_rewards_are_costs_and_penalties(problem):
    model = ViewConeRewardModel(problem)
    assert model.sample(DTState(START, 0), move(2), None) == -3
    assert model.sample(DTState(0, 0), look(0), None) == -1.5
    assert model.sample(DTState(0, 2, True), confirm(0), None) == -70.0
    assert model.sample(DTState(0, 0, True), confirm(0), None) == 0.0
    assert model.sample(DTState(0, 2), REJECT, None) == -50.0
    assert model.sample(DTState(0, NOWHERE), REJECT, None) == 0.0
    assert model.sample(DTState(0, 2, done=True), REJECT, None) == 0.0


def test_valid_actions_skip_zero_prior_cones_and_dominated_moves(problem):
    assert valid_actions(problem, START, False, False, False) == [move(0), move(2), REJECT]
    assert valid_actions(problem, 0, True, False, False) == [look(0), move(2), confirm(0), REJECT]
    assert valid_actions(problem, 0, False, False, True) == [look(0)]
    assert valid_actions(problem, 0, False, True, False) == [REJECT]


def test_greedy_rollout_policy_uses_the_history(problem):
    policy = ViewConePolicyModel(problem, random.Random(0))
    assert policy.rollout(DTState(START, 0), ()) == move(0)
    history = ((move(0), NOTHING),)
    assert policy.rollout(DTState(0, 0), history) == look(0)
