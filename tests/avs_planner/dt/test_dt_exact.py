"""The exact solver: hand-computed optimal values, and it is never beaten by the baselines."""

import random

import pytest

from avs_planner.dt import DetectorModel, DTProblem, DTRewards, TravelCosts, ViewCone
from avs_planner.dt.baselines import GreedyPolicy, SweepPolicy
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import REJECT, move
from avs_planner.dt.exact import ExactSolver, evaluate_policy


def _one_cone(p, fn=0.0, fp=0.0, travel=2.0, sensing=1.0, miss=100.0, horizon=0):
    return DTProblem((ViewCone("a", (1, 0, 0), p),), TravelCosts.from_lists([travel], [[0]]),
                     DetectorModel(fn, fp), sensing, DTRewards(miss, 100.0), horizon)


def test_perfect_detector_one_cone_value_by_hand():
    # move + look (3), then confirm if seen, else reject with nothing left: -3
    problem = _one_cone(0.5)
    solution = ExactSolver(problem).solve(TargetBelief.initial(problem), problem.horizon)
    assert solution.value == pytest.approx(-3.0)
    assert solution.action == move(0)


def test_low_prior_is_not_worth_the_trip():
    # searching costs 3 and saves at most 100 * 0.02 = 2
    problem = _one_cone(0.02)
    solution = ExactSolver(problem).solve(TargetBelief.initial(problem), problem.horizon)
    assert solution.action == REJECT and solution.value == pytest.approx(-2.0)


def test_two_step_horizon_with_false_negatives_by_hand():
    # horizon 2: move, look, then stop. p=0.9, FN=0.2, FP=0
    problem = _one_cone(0.9, fn=0.2, horizon=2)
    solution = ExactSolver(problem).solve(TargetBelief.initial(problem), 2)
    # seen (0.72): confirm, cost 0; missed (0.28): reject, posterior present = 0.18/0.28
    expected = -3.0 - 0.28 * 100.0 * (0.18 / 0.28)
    assert solution.value == pytest.approx(expected)


def _random_problem(rng, n):
    cones = tuple(ViewCone(f"c{i}", (rng.uniform(0, 6), rng.uniform(0, 6), 0.0), 0.0)
                  for i in range(n))
    weights = [rng.random() for _ in cones]
    scale = rng.uniform(0.5, 1.0) / sum(weights)
    cones = tuple(ViewCone(c.id, c.pose, w * scale) for c, w in zip(cones, weights, strict=True))
    return DTProblem(cones, TravelCosts.from_poses((0, 0, 0), cones, speed=1.0),
                     rewards=DTRewards(60.0, 60.0), horizon=2 * n + 2)


@pytest.mark.parametrize("seed", range(4))
def test_exact_is_at_least_as_good_as_baselines(seed):
    problem = _random_problem(random.Random(seed), 3)
    start = TargetBelief.initial(problem)
    solver = ExactSolver(problem)
    best = solver.solve(start, problem.horizon).value
    greedy, sweep = GreedyPolicy(problem), SweepPolicy(problem)
    assert best >= evaluate_policy(problem, greedy.decide, start, problem.horizon) - 1e-9
    assert best >= evaluate_policy(problem, sweep.decide, start, problem.horizon) - 1e-9
    following = evaluate_policy(problem, lambda b, k: solver.solve(b, k).action, start,
                                problem.horizon)
    assert following == pytest.approx(best)
