"""Goals beyond a conjunction of literals: `forall` over objects is grounded and planned for;
a goal that stays a disjunction is refused by `domain check` and `plan` alike, by name."""

from __future__ import annotations

import pytest
from unified_planning.engines.plan_validator import SequentialPlanValidator

from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.errors import PddlError, PlanningError
from avs_planner.pddl import PddlSource, check, read_text
from avs_planner.up_engine import to_up_plan
from tests.avs_planner.cp.pddl_cases import lamps

DOMAIN = """(define (domain lift)
  (:requirements :strips :typing :universal-preconditions :disjunctive-preconditions)
  (:types passenger floor)
  (:predicates (at ?p - passenger ?f - floor) (served ?p - passenger) (in ?p - passenger)
               (dest ?p - passenger ?f - floor) (lift-at ?f - floor))
  (:action move :parameters (?a ?b - floor) :precondition (lift-at ?a)
    :effect (and (lift-at ?b) (not (lift-at ?a))))
  (:action board :parameters (?p - passenger ?f - floor)
    :precondition (and (lift-at ?f) (at ?p ?f)) :effect (and (in ?p) (not (at ?p ?f))))
  (:action leave :parameters (?p - passenger ?f - floor)
    :precondition (and (lift-at ?f) (in ?p) (dest ?p ?f))
    :effect (and (served ?p) (not (in ?p)))))
"""


def _problem(goal: str) -> str:
    return f"""(define (problem two) (:domain lift)
  (:objects p1 p2 - passenger f0 f1 f2 - floor)
  (:init (lift-at f0) (at p1 f0) (at p2 f1) (dest p1 f2) (dest p2 f0))
  (:goal {goal}))
"""


def test_a_forall_goal_is_planned_for_every_object() -> None:
    task = read_text(DOMAIN, _problem("(forall (?p - passenger) (served ?p))"))
    result = plan(task, SearchOptions())
    assert result.status is PlanStatus.SOLVED
    served = {s.args[0] for s in result.plan if s.name == "leave"}
    assert served == {"p1", "p2"}
    check_ = SequentialPlanValidator().validate(task.problem, to_up_plan(task.problem,
                                                                         result.plan))
    assert check_.status.name == "VALID"


def test_a_forall_goal_with_a_negated_body_holding_in_init_needs_no_step() -> None:
    goal = "(and (forall (?p - passenger) (not (in ?p))) (lift-at f0))"
    result = plan(read_text(DOMAIN, _problem(goal)), SearchOptions())
    assert result.status is PlanStatus.SOLVED and result.plan == ()


@pytest.mark.parametrize("goal", ["(or (served p1) (served p2))",
                                  "(exists (?p - passenger) (served ?p))",
                                  "(not (forall (?p - passenger) (at ?p f0)))",
                                  "(imply (served p2) (served p1))"])
def test_a_disjunctive_goal_is_refused_where_it_is(goal: str) -> None:
    text = _problem(goal)
    found = check(PddlSource("d.pddl", DOMAIN), [PddlSource("p.pddl", text)])
    errors = [d for d in found if d.is_error]
    assert [d.code for d in errors] == ["unsupported-goal"]
    assert (errors[0].file, errors[0].line) == ("p.pddl", 4)
    with pytest.raises(PddlError, match="disjunction"):
        read_text(DOMAIN, text, "d.pddl", "p.pddl")


def test_the_grounder_names_a_goal_that_stays_a_disjunction() -> None:
    """Past the reader's check (a problem built in unified-planning directly)."""
    task = read_text(DOMAIN, _problem("(served p1)"))
    problem = task.problem.clone()
    em = problem.environment.expression_manager
    served = problem.fluent("served")
    problem.clear_goals()
    problem.add_goal(em.Or(served(problem.object("p1")), served(problem.object("p2"))))
    with pytest.raises(PlanningError, match=r"grounds to a disjunction \(\(served p1\) or"):
        plan(type(task)(problem), SearchOptions())


def test_too_many_state_dependent_effect_conditions_name_the_ground_action() -> None:
    from avs_planner.cp.conditional import MAX_CONDITIONS

    n = MAX_CONDITIONS + 1
    domain, problem = lamps(n)
    with pytest.raises(PlanningError, match=rf"action flip, as \(flip \): {n} state-dependent"):
        plan(read_text(domain, problem), SearchOptions())
