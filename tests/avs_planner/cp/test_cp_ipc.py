"""Deterministic IPC instances: plans validate with UP's validator; UP engine "avs" works."""

from __future__ import annotations

import pytest
from unified_planning.engines import PlanGenerationResultStatus
from unified_planning.engines.plan_validator import SequentialPlanValidator
from unified_planning.io import PDDLReader
from unified_planning.shortcuts import OneshotPlanner, get_environment

import avs_planner.up_engine  # noqa: F401 - registers the "avs" engine
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.pddl.model import ProbabilisticProblem
from avs_planner.up_engine import to_up_plan
from tests.ipc import require_ipc

INSTANCES = [("blocks", 1), ("blocks", 4), ("gripper", 1), ("logistics", 1), ("elevators", 1)]
get_environment().credits_stream = None


def _read(domain: str, n: int):
    folder = require_ipc() / domain
    return PDDLReader().parse_problem(str(folder / "domain.pddl"),
                                      str(folder / f"instance-{n}.pddl"))


def _validate(problem, up_plan):
    """UP's sequential validator; its kind check rejects elevators' partially defined
    travel costs (UNDEFINED_INITIAL_NUMERIC) although the plan only uses defined ones."""
    validator = SequentialPlanValidator()
    validator.skip_checks = True
    return validator.validate(problem, up_plan)


@pytest.mark.parametrize("domain,n", INSTANCES)
def test_ipc_plan_validates(domain, n):
    problem = _read(domain, n)
    result = plan(ProbabilisticProblem(problem), SearchOptions(weight=2.0))
    assert result.status is PlanStatus.SOLVED
    check = _validate(problem, to_up_plan(problem, result.plan))
    assert check.status.name == "VALID"
    if problem.quality_metrics:
        metric = problem.quality_metrics[0]
        assert float(check.metric_evaluations[metric]) == pytest.approx(result.cost)


def test_w1_hmax_matches_known_optimum_on_blocks():
    problem = _read("blocks", 1)  # 4 blocks; optimal length 6
    result = plan(ProbabilisticProblem(problem), SearchOptions(heuristic="hmax", weight=1.0))
    assert result.cost == 6


def test_up_engine_solves_and_reports_statuses():
    problem = _read("gripper", 1)
    with OneshotPlanner(name="avs", params={"weight": 2.0}) as planner:
        assert planner.supports(problem.kind)
        result = planner.solve(problem)
    assert result.status is PlanGenerationResultStatus.SOLVED_SATISFICING
    assert _validate(problem, result.plan).status.name == "VALID"
    with OneshotPlanner(name="avs", params={"heuristic": "hmax", "weight": 1.0}) as planner:
        optimal = planner.solve(_read("blocks", 1))
    assert optimal.status is PlanGenerationResultStatus.SOLVED_OPTIMALLY
    with OneshotPlanner(name="avs", params={"heuristic": "hmax", "weight": 1.0,
                                            "engine": "python"}) as planner:
        same = planner.solve(_read("blocks", 1))
    assert [str(a) for a in same.plan.actions] == [str(a) for a in optimal.plan.actions]
    assert "replanner[avs]" in get_environment().factory.engines


def test_up_engine_unsolvable_is_proven():
    problem = _read("blocks", 1).clone()
    problem.clear_goals()
    on = problem.fluent("on")
    a = problem.object("a") if problem.has_object("a") else problem.all_objects[0]
    problem.add_goal(on(a, a))  # a block on itself: no action adds it
    with OneshotPlanner(name="avs") as planner:
        result = planner.solve(problem)
    assert result.status is PlanGenerationResultStatus.UNSOLVABLE_PROVEN
