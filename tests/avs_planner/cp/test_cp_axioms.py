"""Derived predicates (PDDL 2.2 `:derived`) in the continual planner: the rules' closure of a
state equals a naive evaluation of their lifted meaning, plans found by either engine are
valid under an independent checker (`derived_semantics.py`), both engines expand the same
states, and what the planner cannot take is refused with its position."""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.cp import axioms, compact, native
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.monitor import MonitorStatus, monitor
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions, search
from avs_planner.cp.symmetry import _named_objects
from avs_planner.errors import PddlError
from avs_planner.pddl import check, read_files, read_text
from avs_planner.pddl.check import PddlSource
from tests.avs_planner.cp.derived_semantics import Semantics

DATA = Path(__file__).parent / "data" / "axioms"
INSTANCES = [(kind, n) for kind in ("blocks", "psr") for n in (1, 2, 3)]
needs_native = pytest.mark.skipif(not native.AVAILABLE, reason="native core not built")


def instance(kind: str, n: int):  # noqa: ANN201 - a ProbabilisticProblem
    return read_files(DATA / f"{kind}-domain.pddl", DATA / f"{kind}-{n}-problem.pddl")


def steps(result) -> list[tuple[str, tuple[str, ...]]]:  # noqa: ANN001
    return [(s.name, tuple(s.args)) for s in result.plan]


def outcome(result) -> tuple:  # noqa: ANN001
    return (result.status, tuple(s.label for s in result.plan), result.cost, result.expanded,
            result.generated)


# ---- plans ------------------------------------------------------------------------------

@pytest.mark.parametrize(("kind", "n"), INSTANCES, ids=lambda x: str(x))
def test_plans_are_valid_and_both_engines_agree(kind: str, n: int) -> None:
    task = instance(kind, n)
    found = plan(task, SearchOptions(engine="python"))
    assert found.status is PlanStatus.SOLVED
    Semantics(task.model).check_plan(steps(found))
    if native.AVAILABLE:
        assert outcome(plan(task, SearchOptions(engine="native"))) == outcome(found)


@pytest.mark.parametrize("heuristic", ["hmax", "hadd", "ff", "blind"])
@pytest.mark.parametrize(("kind", "n"), [("blocks", 1), ("psr", 1), ("psr", 2)],
                         ids=lambda x: str(x))
def test_every_heuristic_and_hmax_stays_admissible(kind: str, n: int, heuristic: str) -> None:
    """A rule is a relaxed action of weight 0 whose negative literals are dropped: h^max
    stays a lower bound, so A* with it finds the optimal cost (that of uniform cost)."""
    task = instance(kind, n)
    engines = ["python", "native"] if native.AVAILABLE else ["python"]
    results = [plan(task, SearchOptions(heuristic=heuristic, weight=1.0, engine=e))
               for e in engines]
    assert len({outcome(r) for r in results}) == 1
    Semantics(task.model).check_plan(steps(results[0]))
    optimal = plan(task, SearchOptions(heuristic="blind", weight=1.0, engine=engines[-1]))
    if heuristic == "hmax":
        assert results[0].cost == optimal.cost


@pytest.mark.parametrize(("kind", "n"), [("blocks", 2), ("psr", 3)], ids=lambda x: str(x))
def test_anytime_mode_plans_are_valid(kind: str, n: int) -> None:
    task = instance(kind, n)
    found = plan(task, SearchOptions(anytime=True, timeout_s=5.0))
    assert found.status is PlanStatus.SOLVED
    Semantics(task.model).check_plan(steps(found))


def test_the_closure_of_the_initial_state_is_in_the_task() -> None:
    task = instance("blocks", 1)
    grounded = ground(task)
    reference = Semantics(task.model).initial()
    assert set(grounded.atoms_of(grounded.init)) == reference
    assert ("above", "a", "b") in reference and ("clear", "c") in reference


def test_a_derived_condition_of_a_conditional_effect_is_read_before_the_action() -> None:
    """psr: closing a switch while a faulty line is fed trips the protection."""
    task = instance("psr", 1)
    grounded = ground(task)
    state = grounded.init
    for label in ("(close-breaker b1)", "(close-switch s1)", "(close-switch s2)"):
        [action] = [a for a in grounded.actions if a.label == label and a.applicable(state)]
        state = grounded.successor(action, state)
        atoms = set(grounded.atoms_of(state))
        if label == "(close-switch s1)":  # l3 is fed now: unsafe, not yet tripped
            assert ("safe",) not in atoms and ("tripped",) not in atoms
    assert ("tripped",) in atoms and ("fed", "l2") in atoms


# ---- the closure -------------------------------------------------------------------------

TOGGLE_DOMAIN = """(define (domain toggles)
  (:requirements :strips :typing :negative-preconditions :disjunctive-preconditions
                 :equality :quantified-preconditions :derived-predicates)
  (:types node)
  (:constants hub - node)
  (:predicates (at ?x - node) (edge ?x ?y - node) (wall ?x - node) (lit ?x - node)
               (reach ?x - node) (blocked ?x - node) (free ?x - node) (dark-all)
               (pair ?x ?y - node) (spoke ?x - node) (goal-ok))
  (:derived (reach ?b - node)
    (or (at ?b) (exists (?a - node) (and (reach ?a) (edge ?a ?b)))))
  (:derived (blocked ?x - node) (or (wall ?x) (and (lit ?x) (not (reach ?x)))))
  (:derived (free ?x - node) (not (blocked ?x)))
  (:derived (dark-all) (forall (?x - node) (imply (reach ?x) (not (lit ?x)))))
  (:derived (pair ?x ?y - node)
    (and (not (= ?x ?y)) (free ?x) (free ?y) (exists (?z - node) (and (edge ?x ?z)
                                                                     (edge ?z ?y)))))
  (:derived (spoke ?x - node) (and (edge hub ?x) (or (free ?x) (dark-all))))
  (:derived (goal-ok)
    (and (spoke hub) (not (dark-all)) (exists (?x ?y - node) (pair ?x ?y))))
  (:action set-at :parameters (?x - node) :effect (at ?x))
  (:action unset-at :parameters (?x - node) :effect (not (at ?x)))
  (:action set-edge :parameters (?x ?y - node) :effect (edge ?x ?y))
  (:action unset-edge :parameters (?x ?y - node) :effect (not (edge ?x ?y)))
  (:action set-wall :parameters (?x - node) :effect (wall ?x))
  (:action unset-wall :parameters (?x - node) :effect (not (wall ?x)))
  (:action set-lit :parameters (?x - node) :effect (lit ?x))
  (:action unset-lit :parameters (?x - node) :effect (not (lit ?x))))
"""
TOGGLE_PROBLEM = """(define (problem toggles-1) (:domain toggles)
  (:objects a b c d - node)
  (:init (at a) (edge a b) (edge b c) (lit d))
  (:goal (goal-ok)))
"""


def _toggles():  # noqa: ANN202
    task = read_text(TOGGLE_DOMAIN, TOGGLE_PROBLEM)
    return task, ground(task, cache=GroundingCache())


def test_every_basic_fact_and_rule_instance_is_reachable_in_the_toggle_domain() -> None:
    task, grounded = _toggles()
    reference = Semantics(task.model)
    nodes = ["hub", "a", "b", "c", "d"]
    basic = {(p, x) for p in ("at", "wall", "lit") for x in nodes}
    basic |= {("edge", x, y) for x in nodes for y in nodes}
    assert basic <= set(grounded.facts)  # so random states over them are reachable ones
    assert reference.strata == {"reach": 0, "blocked": 1, "free": 2, "dark-all": 1,
                                "pair": 2, "spoke": 2, "goal-ok": 2}


@pytest.mark.parametrize("max_disjuncts", [64, 1])
def test_the_closure_equals_a_naive_evaluation_on_random_states(
        max_disjuncts: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """With one disjunct allowed per rule schema, the disjunctions inside conjunctions are
    grounded to clauses instead (`spoke`: a clause of facts of its own stratum)."""
    monkeypatch.setattr(axioms, "MAX_DISJUNCTS", max_disjuncts)
    task, grounded = _toggles()
    assert any(r.clauses and grounded.facts[r.head][0] == "spoke"
               for r in grounded.axioms.rules) == (max_disjuncts == 1)
    reference = Semantics(task.model)
    derived = {i for i, atom in enumerate(grounded.facts) if atom[0] in reference.derived}
    basic = [i for i in range(len(grounded.facts)) if i not in derived]
    rng = random.Random(20261129)
    states = []
    for k in range(300):
        density = (k % 10 + 1) / 12
        states.append(sum(1 << i for i in basic if rng.random() < density)
                      | sum(1 << i for i in derived if rng.random() < 0.5))  # dropped
    for state in states:
        expected = reference.closure(grounded.atoms_of(state))
        assert set(grounded.atoms_of(grounded.axioms.close(state))) == expected
    if native.AVAILABLE:
        assert native.closures(grounded, states) == [grounded.axioms.close(s) for s in states]


@needs_native
def test_estimates_with_rules_are_bit_identical_in_both_engines() -> None:
    task, grounded = _toggles()
    rng = random.Random(3)
    states, state = [], grounded.init
    for _ in range(60):  # a random walk: states the search meets
        applicable = [a for a in grounded.actions if a.applicable(state)]
        state = grounded.successor(rng.choice(applicable), state)
        states.append(state)
    for heuristic in ("ff", "hadd", "hmax"):
        estimator = get_heuristic(heuristic).factory(grounded, 50.0)
        for state, (hc, hl, helpful) in zip(
                states, native.estimates(grounded, heuristic, 50.0, states), strict=True):
            assert (hc, hl) == estimator(state)
            if heuristic == "ff" and hc != math.inf:
                assert frozenset(helpful) == estimator.helpful[state]


ROBOT_DOMAIN = """(define (domain robot)
  (:requirements :strips :typing :derived-predicates :existential-preconditions)
  (:types node)
  (:predicates (at ?x - node) (edge ?x ?y - node) (reach ?x - node) (seen ?x - node))
  (:derived (reach ?b - node)
    (or (at ?b) (exists (?a - node) (and (reach ?a) (edge ?a ?b)))))
  (:action go :parameters (?x ?y - node) :precondition (and (at ?x) (edge ?x ?y))
    :effect (and (not (at ?x)) (at ?y)))
  (:action look :parameters (?x - node) :precondition (reach ?x) :effect (seen ?x)))
"""


def test_only_rule_instances_reachable_from_the_state_are_ground() -> None:
    """Rules are reached like actions: nodes of a component the robot cannot enter get no
    `reach` rules at all, and what it can reach gets them."""
    problem = """(define (problem r) (:domain robot) (:objects a b c x y - node)
      (:init (at a) (edge a b) (edge b c) (edge x y) (edge y x)) (:goal (seen c)))"""
    task = read_text(ROBOT_DOMAIN, problem)
    grounded = ground(task, cache=GroundingCache())
    heads = {grounded.facts[r.head] for r in grounded.axioms.rules}
    assert heads == {("reach", n) for n in "abc"}
    found = plan(task, SearchOptions())
    assert [s.label for s in found.plan] == ["(look c)"]
    Semantics(task.model).check_plan(steps(found))


# ---- the search's pruning and the task's renumbering ---------------------------------------

ORDER_DOMAIN = """(define (domain order)
  (:requirements :strips :derived-predicates)
  (:predicates (e) (d) (done) (other))
  (:derived (d) (e))
  (:action use :parameters () :precondition (d) :effect (done))
  (:action set-e :parameters () :effect (e))
  (:action idle :parameters () :effect (other)))
"""


def test_commutation_pruning_reads_through_derived_facts() -> None:
    """`use` reads only `d`, `set-e` writes only `e`: as bitsets they commute, yet `use`
    needs `set-e` first, since `d` follows from `e`. The order (set-e, use) must survive
    the pruning of commuting orders (`use` has the lower index)."""
    task = read_text(ORDER_DOMAIN, "(define (problem o) (:domain order) (:init) "
                     "(:goal (done)))")
    grounded = ground(task, cache=GroundingCache())
    use, set_e = grounded.action("use", ()), grounded.action("set-e", ())
    assert use.index < set_e.index and use.commutes_with(set_e)
    assert not grounded.axioms.commutes(use, set_e)
    for engine in ("python", "native") if native.AVAILABLE else ("python",):
        for heuristic in ("blind", "ff"):
            found = search(grounded, SearchOptions(engine=engine, heuristic=heuristic))
            assert [s.label for s in found.plan] == ["(set-e)", "(use)"], (engine, heuristic)


def test_a_renumbered_task_keeps_its_rules(monkeypatch: pytest.MonkeyPatch) -> None:
    """`compact` renumbers the facts of large tasks; the rules are renumbered with them."""
    monkeypatch.setattr(compact, "MIN_FACTS", 0)
    monkeypatch.setattr(compact, "MAX_USED_SHARE", 1.0)
    task = instance("blocks", 2)
    grounded = ground(task, cache=GroundingCache())
    assert isinstance(grounded.actions, compact.CompactActions)
    reference = Semantics(task.model)
    for engine in ("python", "native") if native.AVAILABLE else ("python",):
        found = search(grounded, SearchOptions(engine=engine))
        reference.check_plan(steps(found))
    state = grounded.init
    for step in found.plan:
        state = grounded.successor(grounded.action(step.name, step.args), state)
        atoms = set(grounded.atoms_of(state))
        assert atoms == reference.closure(atoms)


def test_the_monitor_closes_the_states_it_walks_through() -> None:
    task = instance("psr", 1)
    grounded = ground(task)
    found = search(grounded, SearchOptions())
    assert monitor(found.plan, grounded).status is MonitorStatus.VALID
    # without its first step (closing the breaker) nothing is fed: the goal is missed
    report = monitor(found.plan[1:], grounded)
    assert report.status is not MonitorStatus.VALID


def test_objects_a_rule_names_are_not_interchangeable() -> None:
    task = read_text(TOGGLE_DOMAIN, TOGGLE_PROBLEM)
    assert "hub" in _named_objects(task)


def test_probabilistic_effects_and_derived_goals_plan_together() -> None:
    domain = ORDER_DOMAIN.replace(":derived-predicates", ":derived-predicates "
                                  ":probabilistic-effects").replace(
        ":effect (e))", ":effect (probabilistic 0.8 (e)))")
    task = read_text(domain, "(define (problem o) (:domain order) (:init) (:goal (done)))")
    found = plan(task, SearchOptions())
    assert [s.label for s in found.plan] == ["(set-e)", "(use)"]
    assert found.probability == pytest.approx(0.8)


# ---- what is refused, and where -----------------------------------------------------------

def _position(text: str, anchor: str) -> tuple[int, int]:
    """1-based line and column of the first `anchor` in `text`."""
    index = text.index(anchor)
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


@pytest.mark.parametrize(("old", "new", "anchor", "code"), [
    ("(:derived (free ?x - node) (not (blocked ?x)))",
     "(:derived (free ?x - node) (not (blocked ?x)))\n"
     "  (:derived (wall ?x - node) (not (free ?x)))", "(blocked ?x)))", "not-stratified"),
    ("(:action set-wall :parameters (?x - node) :effect (wall ?x))",
     "(:action set-wall :parameters (?x - node) :effect (free ?x))", "(free ?x))",
     "derived-in-effect"),
    ("(reach ?a) (edge ?a ?b)", "(reach ?a) (edg ?a ?b)", "edg ", "unknown-predicate"),
    ("(:derived (free ?x - node)", "(:derived (free ?x ?y - node)", "(free ?x ?y",
     "wrong-arity"),
    ("(not (reach ?x))", "(not (reach ?x ?x))", "(reach ?x ?x)", "wrong-arity"),
], ids=["not-stratified", "in-effect", "unknown-predicate", "head-arity", "body-arity"])
def test_plan_and_domain_check_refuse_at_the_same_place(
        old: str, new: str, anchor: str, code: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    assert TOGGLE_DOMAIN.count(old) == 1
    text = TOGGLE_DOMAIN.replace(old, new)
    where = _position(text, anchor)
    domain = tmp_path / "d.pddl"
    domain.write_text(text)
    problem = tmp_path / "p.pddl"
    problem.write_text(TOGGLE_PROBLEM)
    position = f"{domain}:{where[0]}:{where[1]}: "
    assert main(["plan", str(domain), str(problem)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"avs: error: {position}") and "Traceback" not in err, err
    assert main(["domain", "check", str(domain), str(problem)]) == 1
    out = capsys.readouterr().out
    assert any(line.startswith(f"{position}error: ") for line in out.splitlines()), out
    found = check(str(domain), [str(problem)])
    assert (where, code) in [((d.line, d.column), d.code) for d in found if d.is_error]


def test_a_derived_predicate_in_init_is_refused_at_the_fact() -> None:
    problem = TOGGLE_PROBLEM.replace("(lit d)", "(lit d) (free a)")
    with pytest.raises(PddlError) as exc:
        read_text(TOGGLE_DOMAIN, problem, "d.pddl", "p.pddl")
    where = _position(problem, "(free a)")
    assert (exc.value.file, exc.value.line, exc.value.column) == ("p.pddl", *where)
    assert "derived predicate 'free' in :init" in exc.value.message


def test_the_stratification_error_names_the_cycle() -> None:
    domain = TOGGLE_DOMAIN.replace("(:derived (free ?x - node) (not (blocked ?x)))",
                                   "(:derived (free ?x - node) (not (blocked ?x)))\n"
                                   "  (:derived (lit ?x - node) (not (free ?x)))")
    domain = domain.replace("(:action set-lit :parameters (?x - node) :effect (lit ?x))", "")
    domain = domain.replace("(:action unset-lit :parameters (?x - node) :effect (not "
                            "(lit ?x)))", "")
    found = [d for d in check(PddlSource("d.pddl", domain),
                              [PddlSource("p.pddl", TOGGLE_PROBLEM.replace("(lit d)", ""))])
             if d.is_error]
    assert [d.code for d in found] == ["not-stratified"] * 2
    assert [(d.line, d.column) for d in found] == [_position(domain, "(blocked ?x)))"),
                                                   _position(domain, "(free ?x)))\n")]
    assert found[0].message == (
        "derived predicate 'blocked' is negated in the rule for 'free', which it depends on "
        "in turn (free -> blocked -> lit -> free): negation inside a cycle of derived "
        "predicates cannot be stratified")


# ---- the linter on rules ----------------------------------------------------------------

def test_predicates_read_only_by_rules_or_defined_by_them_are_used() -> None:
    for kind in ("blocks", "psr"):
        problems = sorted(str(p) for p in DATA.glob(f"{kind}-*-problem.pddl"))
        assert check(str(DATA / f"{kind}-domain.pddl"), problems) == []
    unused = TOGGLE_DOMAIN.replace("(goal-ok))", "(goal-ok) (lonely))").replace(
        "(:action set-at", "(:derived (lonely) (at hub))\n  (:action set-at")
    found = check(PddlSource("d.pddl", unused), [PddlSource("p.pddl", TOGGLE_PROBLEM)])
    assert [(d.code, d.message) for d in found] == [
        ("unused-predicate", "derived predicate 'lonely' is never used by an action, a goal "
                             "or another rule")]


@pytest.mark.parametrize(("kind", "n"), INSTANCES, ids=lambda x: str(x))
def test_avs_plan_solves_the_instances_with_default_options(
        kind: str, n: int, capsys: pytest.CaptureFixture[str]) -> None:
    domain, problem = DATA / f"{kind}-domain.pddl", DATA / f"{kind}-{n}-problem.pddl"
    assert main(["plan", str(domain), str(problem)]) == 0
    captured = capsys.readouterr()
    lines = [line for line in captured.out.splitlines() if line.startswith("(")]
    assert lines and captured.err == ""
    plan_steps = [(line[1:-1].split()[0], tuple(line[1:-1].split()[1:])) for line in lines]
    Semantics(read_files(domain, problem).model).check_plan(plan_steps)


def test_a_search_from_another_state_closes_it() -> None:
    """A replan from a state that lists derived atoms: the rules decide them."""
    task = instance("blocks", 1)
    cache = GroundingCache()
    first = ground(task, cache=cache)
    wrong = cache.initial_state(task).updated(add=[("clear", "b"), ("handempty",)])
    assert ground(task, wrong, cache).init == first.init
