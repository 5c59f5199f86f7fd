"""pomdp-py models of the multi-label search: distributions sum to one, each label is sensed
with its own detector, rewards are shared costs plus one label's penalty, and pomdp-py's POUCT
plans with them."""

import random
from itertools import product

import pomdp_py
import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    DetectorModel,
    DTRewards,
    LabelTarget,
    MultiLabelProblem,
    MultiObservation,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.domain import NOWHERE, START
from avs_planner.dt.multi import MultiLabelState
from avs_planner.dt.multi.domain import OPEN, confirm_label, look_at, move_to, reject_label
from avs_planner.dt.multi.models import (
    MultiLabelObservationModel,
    MultiLabelPolicyModel,
    MultiLabelRewardModel,
    MultiLabelTransitionModel,
    valid_actions,
)


def _problem(mode="all"):
    cones = (ViewCone("a", (1, 0, 0), 0.0), ViewCone("b", (2, 0, 0), 0.0),
             ViewCone("c", (3, 0, 0), 0.0))
    return MultiLabelProblem(
        cones,
        (LabelTarget("cup", (0.4, 0.0, 0.4), DetectorModel(0.2, 0.05), DTRewards(50.0, 70.0)),
         LabelTarget("book", (0.0, 0.0, 0.5), DetectorModel(0.1, 0.1), DTRewards(30.0, 40.0))),
        TravelCosts.from_lists([1, 2, 3], [[0, 1, 2], [1, 0, 1], [2, 1, 0]]), 1.5, mode)


@pytest.fixture
def problem():
    return _problem()


def _state(robot, targets, detected=(False, False), claims=(OPEN, OPEN), done=False):
    return MultiLabelState(robot, targets, detected, claims, done)


def test_transition_distributions_sum_to_one(problem):
    model = MultiLabelTransitionModel(problem, random.Random(0))
    actions = [move_to(0), look_at(0), look_at(2), confirm_label("cup", 0), reject_label("book")]
    for targets in product([0, 2, NOWHERE], [2, NOWHERE]):
        for claims in [(OPEN, OPEN), (0, OPEN), (OPEN, NOWHERE)]:
            state = _state(0, targets, (True, True), claims)
            for action in actions:
                assert sum(p for _, p in model.successors(state, action)) == pytest.approx(1.0)


def test_a_look_samples_each_label_with_its_own_detector(problem):
    model = MultiLabelTransitionModel(problem, random.Random(1))
    state = _state(2, (2, NOWHERE))  # cup in c, book nowhere
    draws = [model.sample(state, look_at(2)).detected for _ in range(4000)]
    assert sum(d[0] for d in draws) / 4000 == pytest.approx(0.8, abs=0.03)
    assert sum(d[1] for d in draws) / 4000 == pytest.approx(0.1, abs=0.02)
    both = _state(2, (2, NOWHERE), (True, True))
    assert model.probability(both, state, look_at(2)) == pytest.approx(0.8 * 0.1)


def test_a_decided_label_is_not_sensed(problem):
    model = MultiLabelTransitionModel(problem, random.Random(2))
    state = _state(2, (2, 2), claims=(NOWHERE, OPEN))
    assert all(not model.sample(state, look_at(2)).detected[0] for _ in range(200))
    observation = MultiLabelObservationModel().sample(_state(2, (2, 2), (False, True),
                                                              (NOWHERE, OPEN)), look_at(2))
    assert observation == MultiObservation((NOTHING, DETECTED))


def test_claims_set_one_label_and_end_the_search_by_mode():
    for mode, done_after_one_confirm in [("all", False), ("any", True)]:
        problem = _problem(mode)
        model = MultiLabelTransitionModel(problem, random.Random(0))
        state = _state(0, (0, 2), (True, False))
        after = model.sample(state, confirm_label("cup", 0))
        assert after.claims == (0, OPEN) and after.done is done_after_one_confirm
        both = model.sample(model.sample(after, reject_label("book")), reject_label("book"))
        assert both.done


def test_observation_reads_every_open_labels_flag(problem):
    model = MultiLabelObservationModel()
    state = _state(0, (0, 2), (True, False))
    assert model.sample(state, look_at(0)) == MultiObservation((DETECTED, NOT_DETECTED))
    assert model.sample(state, move_to(0)) == MultiObservation((NOTHING, NOTHING))
    assert model.probability(MultiObservation((DETECTED, DETECTED)), state, look_at(0)) == 0.0


def test_rewards_are_shared_costs_and_one_labels_penalty(problem):
    model = MultiLabelRewardModel(problem)
    assert model.sample(_state(START, (0, 2)), move_to(2), None) == -3
    assert model.sample(_state(0, (0, 2)), look_at(0), None) == -1.5
    assert model.sample(_state(0, (2, 2), (True, True)), confirm_label("cup", 0), None) == -70.0
    assert model.sample(_state(0, (0, 2), (True, True)), confirm_label("cup", 0), None) == 0.0
    assert model.sample(_state(0, (0, 0), (True, True)), confirm_label("book", 0), None) == 0.0
    assert model.sample(_state(0, (0, 2)), reject_label("book"), None) == -30.0
    assert model.sample(_state(0, (0, NOWHERE)), reject_label("book"), None) == 0.0
    assert model.sample(_state(0, (0, 2), done=True), reject_label("book"), None) == 0.0


def test_valid_actions(problem):
    labels = problem.labels
    assert valid_actions(problem, START, (False, False), (OPEN, OPEN), False) == [
        move_to(0), move_to(2), reject_label("cup"), reject_label("book")]
    assert valid_actions(problem, 2, (True, False), (OPEN, OPEN), False) == [
        look_at(2), move_to(0), confirm_label("cup", 2), reject_label("cup"),
        reject_label("book")]
    assert valid_actions(problem, 2, (False, False), (OPEN, OPEN), True) == [look_at(2)]
    # only cup is open: book's cones are not worth a move
    assert valid_actions(problem, 0, (False, True), (OPEN, NOWHERE), False) == [
        look_at(0), move_to(2), reject_label(labels[0])]
    assert valid_actions(problem, 0, (False, False), (0, NOWHERE), False) == [reject_label("cup")]


def test_actions_compare_by_what_they_do_not_by_their_motive():
    assert move_to(2, "cup") == move_to(2) and hash(move_to(2, "cup")) == hash(move_to(2))
    assert move_to(2, "cup").label == "cup"
    assert reject_label("cup") != reject_label("book")
    assert str(confirm_label("cup", 2)) == "confirm(cup, 2)"


def test_rollout_follows_the_belief_of_the_history(problem):
    policy = MultiLabelPolicyModel(problem, random.Random(0))
    first = policy.rollout(_state(START, (2, 2)), ())
    assert first == move_to(2)  # both labels may be in c: one look serves both
    history = ((move_to(2), MultiObservation.nothing(2)),)
    assert policy.rollout(_state(2, (2, 2)), history) == look_at(2)


def test_pomdp_py_pouct_plans_with_the_models():
    # pomdp-py's POUCT draws from the `random` module, which tests/conftest.py seeds per test
    cones = (ViewCone("a", (1, 0, 0), 0.0), ViewCone("c", (3, 0, 0), 0.0))
    problem = MultiLabelProblem(
        cones, (LabelTarget("cup", (0.1, 0.8)), LabelTarget("book", (0.0, 0.8))),
        TravelCosts.from_lists([1, 3], [[0, 2], [2, 0]]), 1.0, horizon=4)
    rng = random.Random(0)
    joint = {}
    for targets in product([0, 1, NOWHERE], repeat=2):
        p = 1.0
        for i, t in enumerate(targets):
            p *= problem.single(i).prior[t if t != NOWHERE else problem.n]
        if p > 0.0:
            joint[MultiLabelState.start(START, targets)] = p
    agent = pomdp_py.Agent(pomdp_py.Histogram(joint), MultiLabelPolicyModel(problem, rng),
                           MultiLabelTransitionModel(problem, rng), MultiLabelObservationModel(),
                           MultiLabelRewardModel(problem))
    planner = pomdp_py.POUCT(max_depth=problem.horizon, discount_factor=1.0, num_sims=300,
                             exploration_const=20.0, rollout_policy=agent.policy_model)
    assert planner.plan(agent) == move_to(1)  # both labels are likely in c: one look for both
