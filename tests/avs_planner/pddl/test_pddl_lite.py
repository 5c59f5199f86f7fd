"""The project's own model (`pddl.lite`) is the problem unified-planning's model is.

`read_text` builds a `lite.Problem` where it can and UP's problem of the same text only when
asked (`ProbabilisticProblem.problem`). For every file the project reads (IPC instance 1 of
each domain, the AVS domain with its problems and generated ones, the PDDL files and cases
under `tests/`) both are compared: printed as UP prints them (`canonical` of the fast
reader's test), with the same success expressions, and ground to the same task (ground
action names and arguments, facts, preconditions, effects, clauses, costs and success
probabilities, the initial state and goal). AVS problems are also planned both ways. For
mutated texts, reading with `lite` gives what reading with UP alone gives: the same error,
or the same problem, task and grounding error.
"""

from __future__ import annotations

from dataclasses import replace
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings

from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import SearchOptions
from avs_planner.cp.task import GroundTask
from avs_planner.errors import PddlError
from avs_planner.pddl import ProbabilisticProblem, read_text
from avs_planner.pddl import reader as reader_module
from avs_planner.pddl.lite import is_lite
from bench.avs_generator import AvsSize, generate
from tests.avs_planner.cp.pddl_cases import lamps
from tests.avs_planner.pddl.test_pddl_fast_reader import (
    ADL_DOMAIN,
    ADL_PROBLEM,
    AVS,
    TYPED_PROBLEM,
    TYPED_UNDECLARED_PARENT,
    UNTYPED_DOMAIN,
    UNTYPED_PROBLEM,
    _data_pairs,
    canonical,
    ipc_pairs,
)
from tests.avs_planner.pddl.test_pddl_mutations import AVS as AVS_TEXTS
from tests.avs_planner.pddl.test_pddl_mutations import BASE, mutated


def both(domain: str, problem: str) -> tuple[ProbabilisticProblem, ProbabilisticProblem]:
    """(the read on `lite`, the same read on UP's problem of the text, as before)."""
    read = read_text(domain, problem)
    assert is_lite(read.model), "lite did not take the text"
    return read, replace(read, model=read.problem, success=read.up_success)


def task_dump(task: GroundTask) -> tuple:
    actions = [(a.name, a.args, a.pre, a.pre_neg, a.add, a.delete, a.cost, a.probability,
                a.assumptive, a.clauses) for a in task.actions]
    return (tuple(task.facts), task.init, task.goal, task.goal_neg, task.goal_impossible,
            actions)


def grounded(read: ProbabilisticProblem) -> tuple:
    """The ground task, or what the grounder said."""
    try:
        return task_dump(ground(read, cache=GroundingCache(size=1)))
    except Exception as exc:  # noqa: BLE001 - compared, whatever it is
        return ("raised", type(exc).__name__, str(exc))


def assert_alike(domain: str, problem: str, grounds: bool = True
                 ) -> tuple[ProbabilisticProblem, ProbabilisticProblem]:
    """Printed, with success expressions, and ground alike (or refused alike, where the
    planner refuses the text: `grounds=False`)."""
    fast, up = both(domain, problem)
    assert canonical(fast.model) == canonical(up.model)
    assert {k: str(v) for k, v in fast.success.items()} == {
        k: str(v) for k, v in up.success.items()}
    for name in fast.success:
        assert fast.constant_success(name) == up.constant_success(name)
    found = grounded(fast)
    assert found == grounded(up)
    assert (found[0] != "raised") == grounds, found
    return fast, up


def test_ipc_first_instances_are_alike_in_both_models():
    pairs = ipc_pairs(first_only=True)
    assert len(pairs) >= 21
    for label, domain, problem in pairs:
        try:
            assert_alike(domain.read_text(), problem.read_text())
        except AssertionError as exc:
            raise AssertionError(f"{label}: {exc}") from None


@pytest.mark.parametrize("problem", sorted((AVS / "problems").glob("*.pddl")),
                         ids=lambda p: p.stem)
def test_avs_problems_are_alike_and_plan_alike(problem):
    fast, up = assert_alike((AVS / "domain.pddl").read_text(), problem.read_text())
    options = SearchOptions(timeout_s=None)
    ours, theirs = plan(fast, options), plan(up, options)
    assert [s.label for s in ours.plan] == [s.label for s in theirs.plan]
    assert (ours.status, ours.cost, ours.probability, ours.expanded) == (
        theirs.status, theirs.cost, theirs.probability, theirs.expanded)


@pytest.mark.parametrize("size,seed", [(AvsSize(20, 5, 4, 8), 0), (AvsSize(12, 3, 3, 4), 7),
                                       (AvsSize(40, 8, 6, 12), 3)])
def test_generated_avs_problems_are_alike(size, seed):
    assert_alike((AVS / "domain.pddl").read_text(), generate(size, seed))


@pytest.mark.parametrize("domain,problem", _data_pairs(), ids=lambda p: p.name)
def test_pddl_files_under_tests_are_alike(domain, problem):
    assert_alike(domain.read_text(), problem.read_text(), grounds=domain.stem != "edge-domain")


@pytest.mark.parametrize("domain,problem", [
    (ADL_DOMAIN, ADL_PROBLEM),
    (ADL_DOMAIN, ADL_PROBLEM.replace("minimize (total-cost)", "maximize (load)")),
    (ADL_DOMAIN, ADL_PROBLEM.replace("minimize (total-cost)", "minimize (total-time)")),
    (UNTYPED_DOMAIN, UNTYPED_PROBLEM),
    (TYPED_UNDECLARED_PARENT, TYPED_PROBLEM),
    lamps(5),
], ids=["adl", "maximize", "total-time", "untyped", "typed", "lamps"])
def test_constructs_print_alike(domain, problem):
    """Printed alike; the grounder refuses the ADL case's numeric effects alike."""
    assert_alike(domain, problem, grounds=domain is not ADL_DOMAIN)


def test_an_unmirrored_construct_is_read_by_up():
    """A division of constants (UP's type checker divides their bounds) is left to UP: the
    read is UP's problem, as before."""
    domain = UNTYPED_DOMAIN.replace(
        "(clear ?x))", "(clear ?x))\n  (:functions (f))").replace(
        ":effect (and", ":effect (and (increase (f) (/ 1 2))").replace(
        ":equality", ":equality :numeric-fluents")
    read = read_text(domain, UNTYPED_PROBLEM.replace("(:init", "(:init (= (f) 0)"))
    assert not is_lite(read.model)
    assert read.problem is read.model


# ---- mutated texts: reading with lite gives what reading with UP alone gives -------------

def outcome(domain: str, problem: str) -> tuple:
    try:
        read = read_text(domain, problem, "d.pddl", "p.pddl")
    except PddlError as exc:
        return ("error", str(exc))
    return ("read", canonical(read.model), {k: str(v) for k, v in read.success.items()},
            [str(w) for w in read.warnings], grounded(read))


def assert_same_outcome(domain: str, problem: str) -> None:
    ours = outcome(domain, problem)
    with mock.patch.object(reader_module, "_lite_read", lambda *_args: None):
        assert ours == outcome(domain, problem)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(BASE))
def test_mutated_small_domain_reads_alike(texts: tuple[str, str]) -> None:
    assert_same_outcome(*texts)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(AVS_TEXTS))
def test_mutated_avs_domain_reads_alike(texts: tuple[str, str]) -> None:
    assert_same_outcome(*texts)


CASE_DOMAIN = """(define (domain c)
  (:requirements :adl :typing :numeric-fluents :probabilistic-effects)
  (:types room box - thing)
  (:constants hall - room)
  (:predicates (p ?b - box) (q ?r - room) (flag))
  (:functions (f) (g ?b - box) (pr ?b - box))
  (:action a :parameters (?b - box ?r - room)
    :precondition PRE
    :effect EFF))
"""
CASE_PROBLEM = """(define (problem c1) (:domain c)
  (:objects b1 b2 - box r1 - room)
  (:init (p b1) (= (f) 1) (= (g b1) 2) (= (g b2) 3) (= (pr b1) 0.5) (= (pr b2) 0.25))
  (:goal GOAL))
"""
# (precondition, effect, goal): what UP's model refuses (conflicting numeric effects), what
# lite leaves to UP (a numeric or quantified `when` condition), what the planner refuses
# (numeric conditions and effects), UP's shortcuts and simplifications, probability products
CASES = {
    "conflict": ("(p ?b)", "(and (q ?r) (assign (f) 1) (assign (f) 2))", "(q r1)"),
    "conflict-increase": ("(p ?b)", "(and (q ?r) (increase (f) 1) (assign (f) 2))",
                          "(q r1)"),
    "same-assignment": ("(p ?b)", "(and (q ?r) (assign (f) 1) (assign (f) 1))", "(q r1)"),
    "when-numeric": ("(p ?b)", "(when (> (f) 1) (q ?r))", "(q r1)"),
    "when-exists": ("(p ?b)", "(when (exists (?x - box) (p ?x)) (q ?r))", "(q r1)"),
    "when-equality": ("(p ?b)", "(and (when (= ?r ?r) (q ?r)) (when (= ?r hall) (flag)) "
                      "(when (not (= hall hall)) (p ?b)))", "(q r1)"),
    "when-or": ("(p ?b)", "(when (or (flag) (not (flag))) (q ?r))", "(q r1)"),
    "when-contradiction": ("(p ?b)", "(when (and (flag) (not (flag))) (q ?r))", "(q r1)"),
    "when-imply": ("(p ?b)", "(when (imply (flag) (p ?b)) (q ?r))", "(q r1)"),
    "forall-unused": ("(p ?b)", "(forall (?x - box) (q ?r))", "(q r1)"),
    "forall-when": ("(p ?b)", "(forall (?x - box) (when (p ?x) (q ?r)))", "(q r1)"),
    "not-not": ("(not (not (p ?b)))", "(q ?r)", "(q r1)"),
    "equality-related": ("(and (p ?b) (= ?r ?b))", "(q ?r)", "(q r1)"),
    "numeric-precondition": ("(and (p ?b) (>= (g ?b) 1))", "(q ?r)", "(q r1)"),
    "division-by-zero": ("(p ?b)", "(and (q ?r) (increase (f) (/ (g ?b) 0)))", "(q r1)"),
    "numeric-assignment": ("(p ?b)", "(and (q ?r) (assign (g ?b) (+ (g ?b) 1)))", "(q r1)"),
    "probabilities": ("(p ?b)", "(and (probabilistic 0.5 (q ?r)) (probabilistic 1/2 (flag)) "
                      "(probabilistic (pr ?b) (p ?b)))", "(q r1)"),
    "probability-zero": ("(p ?b)", "(and (probabilistic 0 (q ?r)) "
                         "(probabilistic (pr ?b) (flag)))", "(q r1)"),
    "duplicates-and-true": ("(and (p ?b) (p ?b) (and))", "(q hall)",
                            "(and (q hall) (and) (not (= r1 hall)))"),
    "forall-goal": ("(or (p ?b) (flag))", "(not (p ?b))", "(forall (?r - room) (q ?r))"),
}


@pytest.mark.parametrize("case", CASES)
def test_constructs_read_alike(case: str) -> None:
    precondition, effect, goal = CASES[case]
    assert_same_outcome(CASE_DOMAIN.replace("PRE", precondition).replace("EFF", effect),
                        CASE_PROBLEM.replace("GOAL", goal))

