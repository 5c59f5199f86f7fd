"""POUCT on pomdp-py: exact terminal values in the tree, budgets, tree reuse, closeness to exact."""

import random
import statistics

import pytest

from avs_planner.dt import (
    NOTHING,
    REJECT,
    DetectorModel,
    DTProblem,
    DTRewards,
    SearchBudget,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.baselines import GreedyPolicy
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import NOWHERE, ActionKind
from avs_planner.dt.exact import ExactPolicy, evaluate_policy
from avs_planner.dt.pouct import POUCTPolicy, pouct_decision_rule
from avs_planner.dt.session import DTSession, DTStatus


@pytest.fixture
def problem():
    cones = (ViewCone("a", (2, 0, 0), 0.4), ViewCone("b", (0, 3, 0), 0.3),
             ViewCone("c", (4, 4, 0), 0.1))
    return DTProblem(cones, TravelCosts.from_poses((0, 0, 0), cones), DetectorModel(),
                     2.0, DTRewards(300.0, 300.0))


def test_reject_value_in_tree_is_the_expected_miss_penalty(problem):
    policy = POUCTPolicy(problem, seed=0, budget=SearchBudget(num_sims=100))
    policy.decide(TargetBelief.initial(problem), problem.horizon)
    assert policy.agent.tree[REJECT].value == pytest.approx(-300.0 * 0.8, rel=1e-5)
    assert policy.last_num_sims == 100


def test_time_budget_runs_simulations(problem):
    policy = POUCTPolicy(problem, seed=0, budget=SearchBudget(num_sims=0, planning_time=0.02))
    action = policy.decide(TargetBelief.initial(problem), problem.horizon)
    assert action.kind in (ActionKind.MOVE, ActionKind.REJECT)
    assert policy.last_num_sims > 0


def test_tree_is_reused_after_an_anticipated_observation(problem):
    policy = POUCTPolicy(problem, seed=1, budget=SearchBudget(num_sims=150))
    action = policy.decide(TargetBelief.initial(problem), problem.horizon)
    assert action.kind is ActionKind.MOVE
    visits = policy.agent.tree[action][NOTHING].num_visits
    policy.observe(action, NOTHING)
    assert policy.agent.tree is not None and policy.agent.tree.num_visits == visits
    assert policy.agent.history == ((action, NOTHING),)


def _episode_cost(problem, policy, target, rng):
    session = DTSession.from_problem(problem, policy)
    hit_in, hit_out = problem.detection_rates
    while True:
        action = session.next_action()
        if session.finished:
            break
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            session.update(action, rng.random() < (hit_in if action.cone == target else hit_out))
        else:
            session.update(action)
    belief, result = session.belief, session.result
    if result.status is DTStatus.CONFIRMED:
        return result.cost + 300.0 * (1.0 - belief.probs[result.final_action.cone])
    return result.cost + 300.0 * belief.p_present


@pytest.mark.slow
def test_pouct_expected_cost_between_exact_and_greedy(problem):
    start = TargetBelief.initial(problem)
    optimum = -ExactPolicy(problem).solver.solve(start, problem.horizon).value
    greedy = -evaluate_policy(problem, GreedyPolicy(problem).decide, start, problem.horizon)
    rng = random.Random(5)
    costs = []
    for episode in range(150):
        index = rng.choices(range(4), weights=problem.prior)[0]
        target = NOWHERE if index == 3 else index
        policy = POUCTPolicy(problem, seed=episode)
        costs.append(_episode_cost(problem, policy, target, random.Random(episode)))
    mean = statistics.fmean(costs)
    standard_error = statistics.stdev(costs) / len(costs) ** 0.5
    # measured: exact 37.9, POUCT 39.1 ± 2.8 (session, MC), greedy 54.1 on this instance
    assert optimum - 3 * standard_error <= mean < greedy
    assert mean <= 1.05 * optimum + 3 * standard_error


def test_pouct_expected_cost_is_within_5_percent_of_exact(problem):
    start = TargetBelief.initial(problem)
    optimum = -ExactPolicy(problem).solver.solve(start, problem.horizon).value
    cost = -evaluate_policy(problem, pouct_decision_rule(problem, seed=0), start,
                            problem.horizon)
    # measured: 38.06 against the optimum 37.91 (+0.4%)
    assert optimum - 1e-9 <= cost <= 1.05 * optimum
