"""Goals beyond a conjunction of literals. A `forall` over objects is grounded to literals as
before (no rule); a goal with `or`, `exists`, `imply`, or an `and`/`forall` under a `not`
becomes one derived fact (`cp/goal.py`), planned for by both engines, its plans valid by
unified-planning's validator, and `avs domain check` accepts what `avs plan` plans for and
refuses what it refuses, at the same place."""

from __future__ import annotations

from pathlib import Path

import pytest
from unified_planning.engines.plan_validator import SequentialPlanValidator

from avs_planner.cli import main
from avs_planner.cp import native
from avs_planner.cp.goal import GOAL_NAME
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.errors import PddlError
from avs_planner.pddl import PddlSource, check, read_text
from avs_planner.up_engine import to_up_plan
from tests.avs_planner.cp.derived_semantics import Semantics
from tests.avs_planner.cp.pddl_cases import LIFT as DOMAIN
from tests.avs_planner.cp.pddl_cases import lift_problem as _problem

ENGINES = ["python", "native"] if native.AVAILABLE else ["python"]


def _valid(task, result) -> bool:  # noqa: ANN001
    """UP's validator on the UP problem of the same text (it reads any goal formula)."""
    found = SequentialPlanValidator().validate(task.problem,
                                               to_up_plan(task.problem, result.plan))
    return found.status.name == "VALID"


def _outcome(result) -> tuple:  # noqa: ANN001
    return (result.status, tuple(s.label for s in result.plan), result.cost, result.expanded,
            result.generated)


def test_a_forall_goal_is_planned_for_every_object_without_a_rule() -> None:
    task = read_text(DOMAIN, _problem("(forall (?p - passenger) (served ?p))"))
    grounded = ground(task, cache=GroundingCache())
    assert grounded.axioms is None  # a conjunction of literals: goal bitsets, as always
    assert {grounded.facts[i] for i in range(len(grounded.facts))
            if grounded.goal >> i & 1} == {("served", "p1"), ("served", "p2")}
    result = plan(task, SearchOptions())
    assert result.status is PlanStatus.SOLVED
    served = {s.args[0] for s in result.plan if s.name == "leave"}
    assert served == {"p1", "p2"}
    assert _valid(task, result)


def test_a_forall_goal_with_a_negated_body_holding_in_init_needs_no_step() -> None:
    goal = "(and (forall (?p - passenger) (not (in ?p))) (lift-at f0))"
    result = plan(read_text(DOMAIN, _problem(goal)), SearchOptions())
    assert result.status is PlanStatus.SOLVED and result.plan == ()


GOALS = {  # goal -> the length of an optimal plan
    "or": ("(or (served p1) (served p2))", 3),
    "exists": ("(exists (?p - passenger) (served ?p))", 3),
    "imply": ("(imply (in p1) (served p2))", 0),
    "imply-needing-steps": ("(and (in p1) (imply (in p1) (lift-at f2)))", 2),
    "not-and": ("(and (in p2) (not (and (lift-at f1) (in p2))))", 3),
    "not-forall": ("(and (in p1) (not (forall (?f - floor) (not (lift-at ?f)))))", 1),
    "forall-of-or": ("(forall (?p - passenger) (or (served ?p) (in ?p)))", 3),
    "forall-exists": ("(forall (?p - passenger) (exists (?f - floor) "
                      "(and (dest ?p ?f) (or (served ?p) (lift-at ?f)))))", 4),
    "or-of-ands": ("(or (and (served p1) (at p2 f1)) (and (in p2) (lift-at f2)))", 3),
}


@pytest.mark.parametrize("name", GOALS)
def test_a_goal_that_is_no_conjunction_of_literals_is_planned_for(name: str) -> None:
    goal, length = GOALS[name]
    task = read_text(DOMAIN, _problem(goal))
    grounded = ground(task, cache=GroundingCache())
    assert grounded.facts[grounded.goal.bit_length() - 1] == (GOAL_NAME,)
    assert grounded.goal.bit_count() == 1 and grounded.goal_neg == 0
    results = [plan(task, SearchOptions(engine=e, heuristic="hmax", weight=1.0))
               for e in ENGINES]
    assert len({_outcome(r) for r in results}) == 1  # both engines: same plan, same counts
    found = results[0]
    assert found.status is PlanStatus.SOLVED and len(found.plan) == length
    assert _valid(task, found)
    Semantics(task.model).check_plan([(s.name, tuple(s.args)) for s in found.plan])
    default = plan(task, SearchOptions())  # weighted A* with FF, the default
    assert default.status is PlanStatus.SOLVED and _valid(task, default)


@pytest.mark.parametrize("name", GOALS)
def test_domain_check_accepts_what_plan_plans_for(name: str) -> None:
    found = check(PddlSource("d.pddl", DOMAIN), [PddlSource("p.pddl", _problem(GOALS[name][0]))])
    assert [d for d in found if d.is_error] == []


def test_a_goal_built_in_unified_planning_is_planned_for() -> None:
    """Past the reader (a problem built in unified-planning directly): the grounder
    compiles the disjunction it once refused."""
    task = read_text(DOMAIN, _problem("(served p1)"))
    problem = task.problem.clone()
    em = problem.environment.expression_manager
    served = problem.fluent("served")
    problem.clear_goals()
    problem.add_goal(em.Or(served(problem.object("p1")), served(problem.object("p2"))))
    built = type(task)(problem)
    result = plan(built, SearchOptions())
    assert result.status is PlanStatus.SOLVED and len(result.plan) == 3
    assert _valid(built, result)


def test_a_goal_holding_in_init_through_one_disjunct_gives_the_empty_plan(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = _problem("(or (served p2) (exists (?f - floor) (and (lift-at ?f) (at p1 ?f))))")
    for engine in ENGINES:
        result = plan(read_text(DOMAIN, text), SearchOptions(engine=engine))
        assert result.status is PlanStatus.SOLVED and result.plan == ()
        assert result.expanded == 0
    found = check(PddlSource("d.pddl", DOMAIN), [PddlSource("p.pddl", text)])
    assert not [d for d in found if d.is_error]
    assert [(d.line, d.column) for d in found if d.code == "goal-true-in-init"] == [(4, 3)]
    domain, problem = _write(tmp_path, text)
    assert main(["plan", domain, problem]) == 0
    assert capsys.readouterr().out.startswith("; cost: 0\n")


@pytest.mark.parametrize("goal", [
    "(or (at p1 f2) (at p2 f2))",  # atoms no action adds: decided while grounding
    "(or (and (served p1) (at p1 f0)) (and (served p2) (at p2 f1)))",  # found by the search
], ids=["decided-while-grounding", "search-exhausted"])
def test_an_unreachable_disjunctive_goal_has_no_plan(
        goal: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    task = read_text(DOMAIN, _problem(goal))
    for engine in ENGINES:
        assert plan(task, SearchOptions(engine=engine)).status is PlanStatus.UNSOLVABLE
    domain, problem = _write(tmp_path, _problem(goal))
    assert main(["plan", domain, problem]) == 2
    captured = capsys.readouterr()
    assert "; status: unsolvable" in captured.out and "Traceback" not in captured.err


def test_a_numeric_comparison_inside_a_disjunction_is_refused_where_it_is(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    domain_text = DOMAIN.replace(":negative-preconditions)",
                                 ":negative-preconditions :numeric-fluents)").replace(
        "(lift-at ?f - floor))", "(lift-at ?f - floor))\n  (:functions (load))")
    text = _problem("(or (served p1) (> (load) 2))").replace("(dest p2 f0))",
                                                             "(dest p2 f0) (= (load) 1))")
    found = [d for d in check(PddlSource("d.pddl", domain_text), [PddlSource("p.pddl", text)])
             if d.is_error]
    line, column = _position(text, "(> (load)")
    assert [(d.code, d.line, d.column) for d in found] == [("unsupported-goal", line, column)]
    with pytest.raises(PddlError, match=r"numeric condition \(> \(load\) 2\) in the goal"):
        read_text(domain_text, text, "d.pddl", "p.pddl")
    domain, problem = _write(tmp_path, text, domain_text)
    assert main(["plan", domain, problem]) == 1
    assert f"avs: error: {problem}:{line}:{column}: " in capsys.readouterr().err


def _write(tmp_path: Path, problem_text: str, domain_text: str = DOMAIN) -> tuple[str, str]:
    (tmp_path / "d.pddl").write_text(domain_text)
    (tmp_path / "p.pddl").write_text(problem_text)
    return str(tmp_path / "d.pddl"), str(tmp_path / "p.pddl")


def _position(text: str, anchor: str) -> tuple[int, int]:
    """1-based line and column of the first `anchor` in `text`."""
    index = text.index(anchor)
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1
