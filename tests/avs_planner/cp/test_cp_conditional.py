"""Conditional effects (`when`, `forall` in effects): grounded, searched, plans valid under
UP's validator."""

from __future__ import annotations

from pathlib import Path

import pytest
from unified_planning.engines.plan_validator import SequentialPlanValidator

from avs_planner.cp.grounding import ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.pddl import read_files
from avs_planner.up_engine import to_up_plan
from tests.ipc import require_ipc

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def briefcase():
    return read_files(DATA / "briefcase-domain.pddl", DATA / "briefcase-problem.pddl")


@pytest.mark.parametrize("options", [
    SearchOptions(), SearchOptions(heuristic="hmax", weight=1.0), SearchOptions(engine="python"),
    SearchOptions(heuristic="hadd"),
], ids=["ff", "hmax-w1", "python", "hadd"])
def test_briefcase_plans_are_valid(briefcase, options: SearchOptions) -> None:
    """Moving the case moves what is in it, unless it is locked: the plan must unlock."""
    result = plan(briefcase, options)
    assert result.status is PlanStatus.SOLVED and briefcase.warnings == ()
    labels = [s.label for s in result.plan]
    assert "(toggle-lock)" in labels and labels.index("(toggle-lock)") < labels.index(
        "(move home office)")
    check = SequentialPlanValidator().validate(
        briefcase.problem, to_up_plan(briefcase.problem, result.plan))
    assert check.status.name == "VALID"
    if options.weight == 1.0:
        assert result.cost == 7


def test_state_dependent_conditions_split_the_action(briefcase) -> None:
    task = ground(briefcase)
    toggles = [a for a in task.actions if a.name == "toggle-lock"]
    assert len(toggles) == 2  # locked -> unlock, not locked -> lock
    locked = task.fact_index[("locked",)]
    assert {(a.pre >> locked & 1, a.pre_neg >> locked & 1) for a in toggles} == {(1, 0), (0, 1)}
    moves = [a for a in task.actions if a.label == "(move home office)"]
    assert len(moves) > 1 and len({a.label for a in moves}) == 1


def test_static_conditions_become_plain_effects() -> None:
    """maintenance: `(forall (?plane) (when (at ?plane ?day ?airport) (done ?plane)))`,
    `at` static: one copy per ground action, adding exactly the planes there that day."""
    folder = require_ipc() / "maintenance"
    task = ground(read_files(folder / "domain.pddl", folder / "instance-1.pddl"))
    (workat,) = [a for a in task.actions if a.label == "(workat d1 fra)"]
    done = {task.facts[i] for i in range(len(task.facts)) if workat.add >> i & 1}
    assert done == {("done", p) for p in ("ap2", "ap28", "ap51", "ap117", "ap121", "ap132")}
    assert not workat.clauses
    assert len({a.label for a in task.actions}) == len(task.actions)


def test_up_engine_takes_conditional_effects() -> None:
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import OneshotPlanner

    import avs_planner.up_engine  # noqa: F401 - registers "avs"

    problem = PDDLReader().parse_problem(str(DATA / "briefcase-domain.pddl"),
                                         str(DATA / "briefcase-problem.pddl"))
    with OneshotPlanner(name="avs", params={"anytime": True}) as planner:
        assert planner.supports(problem.kind)
        result = planner.solve(problem, timeout=30)
    assert result.status.name == "SOLVED_SATISFICING"
    assert SequentialPlanValidator().validate(problem, result.plan).status.name == "VALID"
