"""Search: optimality at w = 1 against brute force, statuses, the first plan of the active visual
search paper."""

from __future__ import annotations

import math

import pytest

from avs_planner.cp import native
from avs_planner.cp.grounding import ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions, objective
from avs_planner.errors import PlanningError

R = 100.0
# the brute-force checks run on both search engines (native: the compiled core)
ENGINES = ["python", pytest.param("native", marks=pytest.mark.skipif(
    not native.AVAILABLE, reason="native core not built (test_cp_native fails for that)"))]


def brute_force(task, reward: float) -> float:
    """Best objective over all loop-free action sequences (revisiting never pays)."""
    best = math.inf
    if task.goal_impossible:  # a goal atom no action touches and :init makes false
        return best

    def dfs(state: int, c: float, p: float, seen: frozenset[int]) -> None:
        nonlocal best
        if task.is_goal(state):
            best = min(best, objective(c, p, reward))
        for a in task.actions:
            if a.applicable(state):
                nxt = a.apply(state)
                if nxt not in seen:
                    dfs(nxt, c + a.cost, p * a.probability, seen | {nxt})

    dfs(task.init, 0.0, 1.0, frozenset([task.init]))
    return best


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("heuristic", ["hmax", "blind"])
def test_w1_admissible_is_optimal_against_brute_force(heuristic, engine, make_random):
    checked = 0
    for seed in range(60):
        pproblem = make_random(seed)
        task = ground(pproblem)
        expected = brute_force(task, R)
        result = plan(pproblem, SearchOptions(reward=R, heuristic=heuristic, weight=1.0,
                                              engine=engine))
        assert result.extra["engine"] == engine
        if expected == math.inf:
            assert result.status is PlanStatus.UNSOLVABLE, seed
            continue
        checked += 1
        assert result.status is PlanStatus.SOLVED, seed
        assert result.objective == pytest.approx(expected), seed
    assert checked >= 20  # enough solvable instances were actually compared


@pytest.mark.parametrize("engine", ENGINES)
def test_satisficing_plans_are_valid_and_no_better_than_optimal(engine, make_random):
    for seed in range(30):
        pproblem = make_random(seed)
        task = ground(pproblem)
        expected = brute_force(task, R)
        result = plan(pproblem, SearchOptions(reward=R, heuristic="ff", weight=3.0,
                                              engine=engine))
        if expected == math.inf:
            continue
        state = task.init
        for step in result.plan:
            action = task.action(step.name, step.args)
            assert action.applicable(state)
            state = action.apply(state)
        assert task.is_goal(state)
        assert result.objective >= expected - 1e-9


def test_seed_first_plan_from_corridor(corridor):
    result = plan(corridor, SearchOptions(reward=500.0))
    assert result.status is PlanStatus.SOLVED
    assert [s.label for s in result.plan] == [
        "(assume-leads-to-room place1 kitchen new-room1)",
        "(assume-obj-exists-in table new-room1 kitchen new-object1)",
        "(assume-obj-exists-on cerealbox new-object1 table kitchen new-room1 new-object2)",
        "(move place0 place1)",
        "(createviewcones-in table new-room1)",
        "(searchforobject-in table new-room1 new-object1 place1)",
        "(createviewcones-on cerealbox new-object1)",
        "(searchforobject-on cerealbox new-object1 new-object2 new-room1 place1)",
        "(reportposition new-object2 cerealbox)",
    ]
    assert result.probability == pytest.approx(0.6 * 0.9 * 0.6 * 0.8 * 0.8)
    assert result.cost == pytest.approx(56.0)


def test_corridor_symmetry_pruning_keeps_the_optimum(corridor):
    with_sym = plan(corridor, SearchOptions(reward=500.0, heuristic="hmax", weight=1.0))
    without = plan(corridor, SearchOptions(
        reward=500.0, heuristic="hmax", weight=1.0, symmetry=False))
    assert with_sym.objective == pytest.approx(without.objective)
    assert with_sym.expanded < without.expanded


def test_min_success_threshold_and_limits(corridor):
    high = plan(corridor, SearchOptions(reward=500.0, min_success=0.5))
    assert high.status is PlanStatus.NO_PLAN_ABOVE_THRESHOLD
    limited = plan(corridor, SearchOptions(reward=500.0, node_limit=1))
    assert limited.status is PlanStatus.NODE_LIMIT
    timed = plan(corridor, SearchOptions(reward=500.0, heuristic="blind", timeout_s=1e-9))
    assert timed.status is PlanStatus.TIMEOUT


def test_unknown_heuristic_and_bad_options_are_errors():
    with pytest.raises(PlanningError, match="unknown heuristic"):
        SearchOptions(heuristic="nope").check()
    with pytest.raises(PlanningError, match="weight"):
        SearchOptions(weight=0.5).check()
