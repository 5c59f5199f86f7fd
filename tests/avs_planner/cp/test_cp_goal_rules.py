"""A goal compiled into a derived fact (`cp/goal.py`) downstream: its closure equals a naive
evaluation of the goal formula on random states (over derived predicates too, in both
engines' closures), the rules stay linear in the ground formula, and the search's objective,
the monitor, the continual planner, the symmetry pruning, the renumbered fact table, the
grounding cache, the anytime mode and the unified-planning engine all read it. A goal that
is a conjunction of literals takes the path it always took (same plans, same counts)."""

from __future__ import annotations

import hashlib
import random
from pathlib import Path

import pytest
from unified_planning.engines import PlanGenerationResultStatus
from unified_planning.engines.plan_validator import SequentialPlanValidator
from unified_planning.shortcuts import OneshotPlanner, get_environment

import avs_planner.up_engine  # noqa: F401 - registers the "avs" engine
from avs_planner.cli import main
from avs_planner.cp import compact, goal, native
from avs_planner.cp.continual import ContinualPlanner, Decision
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.monitor import MonitorStatus, monitor
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.cp.symmetry import find_symmetries
from avs_planner.cp.unsupported import UnsupportedError
from avs_planner.pddl import read_files, read_text
from avs_planner.up_engine import to_up_plan
from tests.avs_planner.cp.derived_semantics import Semantics
from tests.avs_planner.cp.pddl_cases import LIFT, lift_problem
from tests.avs_planner.cp.test_cp_axioms import TOGGLE_DOMAIN, TOGGLE_PROBLEM
from tests.ipc import IPC

ENGINES = ["python", "native"] if native.AVAILABLE else ["python"]
DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).resolve().parents[3]
get_environment().credits_stream = None


def steps(result) -> list[tuple[str, tuple[str, ...]]]:  # noqa: ANN001
    return [(s.name, tuple(s.args)) for s in result.plan]


def outcome(result) -> tuple:  # noqa: ANN001
    return (result.status, tuple(s.label for s in result.plan), result.cost, result.expanded,
            result.generated)


# ---- the closure against the formula's meaning --------------------------------------------

TOGGLE_GOALS = [
    "(or (not (free a)) (and (goal-ok) (exists (?x - node) (and (lit ?x) (not (reach ?x))))))",
    "(forall (?x - node) (imply (reach ?x) (or (free ?x) (spoke ?x))))",
    "(not (and (dark-all) (exists (?x ?y - node) (pair ?x ?y))))",
    "(exists (?x - node) (and (not (reach ?x)) (forall (?y - node) (or (= ?x ?y) "
    "(not (edge ?y ?x)) (blocked ?y)))))",
]


@pytest.mark.parametrize("formula", TOGGLE_GOALS, ids=range(len(TOGGLE_GOALS)))
def test_the_goal_fact_holds_exactly_where_the_goal_does(formula: str) -> None:
    """Over derived predicates (negated ones too): on random states, the goal atom of the
    closure (Python and C) is the naive evaluation of the goal after the rules."""
    task = read_text(TOGGLE_DOMAIN, TOGGLE_PROBLEM.replace("(:goal (goal-ok))",
                                                           f"(:goal {formula})"))
    grounded = ground(task, cache=GroundingCache())
    reference = Semantics(task.model)
    [head] = [i for i in range(len(grounded.facts)) if grounded.goal >> i & 1]
    assert grounded.facts[head] == (goal.GOAL_NAME,)
    read = {f for r in grounded.axioms.rules if grounded.facts[r.head][0].startswith("@goal")
            for f in (*r.pos, *r.neg) if not grounded.facts[f][0].startswith("@goal")}
    strata = {r.head: r.stratum for r in grounded.axioms.rules}
    goal_level = strata[head]
    assert all(strata.get(f, -1) < goal_level for f in read)  # above what the goal reads
    own = {i for i, a in enumerate(grounded.facts) if a[0].startswith("@goal")}
    derived = {i for i, a in enumerate(grounded.facts) if a[0] in reference.derived} | own
    basic = [i for i in range(len(grounded.facts)) if i not in derived]
    fixed = {a for a in reference.initial() if a[0] not in reference.derived
             and a not in grounded.fact_index}  # no action changes them
    rng = random.Random(20261130)
    states = [sum(1 << i for i in basic if rng.random() < (k % 10 + 1) / 12)
              for k in range(300)]
    held = 0
    for state in states:
        closed = grounded.axioms.close(state)
        expected = reference.goal_holds(reference.closure({*grounded.atoms_of(state), *fixed}))
        assert grounded.is_goal(closed) == expected
        held += expected
    assert 0 < held < len(states)  # both outcomes are met
    if native.AVAILABLE:
        assert native.closures(grounded, states) == [grounded.axioms.close(s) for s in states]


@pytest.mark.parametrize("formula", TOGGLE_GOALS, ids=range(len(TOGGLE_GOALS)))
def test_plans_for_goals_over_derived_predicates_are_valid(formula: str) -> None:
    task = read_text(TOGGLE_DOMAIN, TOGGLE_PROBLEM.replace("(:goal (goal-ok))",
                                                           f"(:goal {formula})"))
    results = [plan(task, SearchOptions(engine=e)) for e in ENGINES]
    assert len({outcome(r) for r in results}) == 1
    assert results[0].status is PlanStatus.SOLVED
    Semantics(task.model).check_plan(steps(results[0]))


@pytest.mark.parametrize(("formula", "length"), [
    ("(or (not (handempty)) (above b a))", 1),  # a derived atom negated in the goal
    ("(imply (above a b) (above c a))", 1),
    ("(exists (?x - block) (and (above ?x a) (not (clear ?x))))", 6),
], ids=["not-derived", "imply-derived", "exists-derived"])
def test_blocks_goals_over_derived_predicates(formula: str, length: int) -> None:
    text = (DATA / "axioms" / "blocks-1-problem.pddl").read_text().replace(
        "(:goal (and (above c a) (ontable b)))", f"(:goal {formula})")
    task = read_text((DATA / "axioms" / "blocks-domain.pddl").read_text(), text)
    results = [plan(task, SearchOptions(engine=e, heuristic="hmax", weight=1.0))
               for e in ENGINES]
    assert len({outcome(r) for r in results}) == 1
    assert len(results[0].plan) == length  # optimal (h^max stays admissible)
    Semantics(task.model).check_plan(steps(results[0]))


def test_rules_grow_with_the_ground_formula_not_its_normal_form() -> None:
    """A disjunction per passenger under a `forall`: as a CNF or DNF, 2^40 clauses or
    disjuncts; as rules, one auxiliary fact and two rules per passenger."""
    passengers = [f"q{i}" for i in range(40)]
    text = f"""(define (problem many) (:domain lift)
  (:objects {' '.join(passengers)} - passenger f0 f1 - floor)
  (:init (lift-at f0) {' '.join(f'(at {p} f1) (dest {p} f0)' for p in passengers)})
  (:goal (forall (?p - passenger) (or (served ?p) (in ?p)))))
"""
    task = read_text(LIFT, text)
    grounded = ground(task, cache=GroundingCache())
    assert len(grounded.axioms) == 2 * len(passengers) + 1
    result = plan(task, SearchOptions())
    assert result.status is PlanStatus.SOLVED
    Semantics(task.model).check_plan(steps(result))


def test_a_goal_too_large_to_ground_is_refused_at_one_place(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """What the grounder still refuses in a goal, `avs plan` and `avs domain check` (which
    grounds each problem) refuse at the same position, without a traceback."""
    monkeypatch.setattr(goal, "MAX_GOAL_ATOMS", 5)
    text = lift_problem("(forall (?p - passenger) (exists (?f - floor) (or (at ?p ?f) "
                        "(lift-at ?f))))")
    with pytest.raises(UnsupportedError, match=r"^p\.pddl:4:10: unsupported goal condition "
                       r".*: the goal grounds to more than 5 atoms"):
        ground(read_text(LIFT, text, "d.pddl", "p.pddl"), cache=GroundingCache())
    (tmp_path / "d.pddl").write_text(LIFT)
    (tmp_path / "p.pddl").write_text(text)
    domain, problem = str(tmp_path / "d.pddl"), str(tmp_path / "p.pddl")
    assert main(["plan", domain, problem]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"avs: error: {problem}:4:10: unsupported goal condition ")
    assert "Traceback" not in err
    assert main(["domain", "check", domain, problem]) == 1
    out = capsys.readouterr().out
    assert f"{problem}:4:10: error: unsupported goal condition " in out
    assert "more than 5 atoms" in out


def test_a_fluent_named_like_the_goal_moves_the_goal_aside() -> None:
    class Named:
        def __init__(self, name: str):
            self.name = name

    class Problem:
        fluents = [Named("@goal"), Named("@goal'.1")]

    assert goal.goal_name(Problem()) == "@goal''"


# ---- the objective, the monitor, the continual planner ------------------------------------

GAMBLE = """(define (domain gamble)
  (:requirements :strips :probabilistic-effects :action-costs :disjunctive-preconditions)
  (:predicates (a) (b))
  (:functions (total-cost) - number)
  (:action get-a :parameters () :effect (and (probabilistic 0.5 (a))
                                              (increase (total-cost) 1)))
  (:action get-b :parameters () :effect (and (probabilistic 0.95 (b))
                                              (increase (total-cost) 5))))
"""
GAMBLE_PROBLEM = """(define (problem g) (:domain gamble) (:init (= (total-cost) 0))
  (:goal (or (a) (b))) (:metric minimize (total-cost)))
"""


@pytest.mark.parametrize(("reward", "chosen", "probability"), [
    (500.0, "get-b", 0.95),  # 1 + 500 * 0.5 = 251 against 5 + 500 * 0.05 = 30
    (4.0, "get-a", 0.5),  # 1 + 2 = 3 against 5 + 0.2
])
def test_the_objective_weighs_each_way_to_the_goal(reward: float, chosen: str,
                                                   probability: float) -> None:
    task = read_text(GAMBLE, GAMBLE_PROBLEM)
    for engine in ENGINES:
        result = plan(task, SearchOptions(engine=engine, reward=reward))
        assert [s.name for s in result.plan] == [chosen]
        assert result.probability == pytest.approx(probability)


def test_the_monitor_reads_the_goal_fact() -> None:
    task = read_text(LIFT, lift_problem("(or (served p1) (served p2))"))
    grounded = ground(task, cache=GroundingCache())
    result = plan(task, SearchOptions())
    assert monitor(result.plan, grounded).status is MonitorStatus.VALID
    assert monitor(result.plan[:-1], grounded).status is MonitorStatus.GOAL_NOT_REACHED
    # the other disjunct came true meanwhile: nothing is left to do
    served = grounded.state_of([("served", "p2"), ("lift-at", "f0")])
    assert monitor((), grounded, served).status is MonitorStatus.VALID


def test_the_continual_planner_replans_to_the_other_disjunct() -> None:
    task = read_text(LIFT, lift_problem("(or (served p1) (served p2))"))
    planner = ContinualPlanner(task, SearchOptions())
    first = planner.replan()
    assert first.solved and first.plan[0].label == "(board p1 f0)"
    # p1 left the building (no longer at f0): its plan breaks, p2 is served instead
    moved = planner.state.updated(delete=[("at", "p1", "f0")])
    update = planner.update(moved)
    assert update.decision is Decision.REPLANNED
    assert update.report.status is MonitorStatus.PRECONDITION_FAILED
    assert update.plan[-1].label == "(leave p2 f0)"
    # p2 turns out served already (and gone from f1): the new plan breaks too, and the goal
    # holds through the other disjunct, so the plan made now is empty
    done = moved.updated(add=[("served", "p2")], delete=[("at", "p2", "f1")])
    again = planner.update(done)
    assert again.decision is Decision.REPLANNED and again.plan == ()
    assert planner.check(done).status is MonitorStatus.VALID


# ---- symmetries, renumbering, the cache, anytime, the UP engine --------------------------

BALLS = """(define (domain balls)
  (:requirements :strips :typing :existential-preconditions :equality
                 :negative-preconditions :disjunctive-preconditions)
  (:types ball room)
  (:predicates (at ?b - ball ?r - room) (robot-at ?r - room) (carry ?b - ball))
  (:action move :parameters (?a ?b - room) :precondition (robot-at ?a)
    :effect (and (robot-at ?b) (not (robot-at ?a))))
  (:action pick :parameters (?b - ball ?r - room)
    :precondition (and (robot-at ?r) (at ?b ?r)) :effect (and (carry ?b) (not (at ?b ?r))))
  (:action drop :parameters (?b - ball ?r - room)
    :precondition (and (robot-at ?r) (carry ?b)) :effect (and (at ?b ?r) (not (carry ?b)))))
"""
TWO_BALLS = "(exists (?x ?y - ball) (and (not (= ?x ?y)) (at ?x r2) (at ?y r2)))"


def _balls(goal_text: str, count: int = 6) -> str:
    balls = " ".join(f"b{i}" for i in range(count))
    return f"""(define (problem b) (:domain balls)
  (:objects {balls} - ball r1 r2 - room)
  (:init (robot-at r1) {' '.join(f'(at b{i} r1)' for i in range(count))})
  (:goal {goal_text}))
"""


def test_interchangeable_objects_are_pruned_under_a_quantified_goal() -> None:
    task = read_text(BALLS, _balls(TWO_BALLS))
    grounded = ground(task, cache=GroundingCache())
    state = GroundingCache().initial_state(task)
    assert find_symmetries(task, state, grounded).groups  # the balls are interchangeable
    pruned = [plan(task, SearchOptions(heuristic="hmax", weight=1.0, engine=e))
              for e in ENGINES]
    assert len({outcome(r) for r in pruned}) == 1
    full = plan(task, SearchOptions(heuristic="hmax", weight=1.0, symmetry=False))
    assert pruned[0].cost == full.cost == 5  # pick, pick, move, drop, drop
    assert pruned[0].expanded < full.expanded
    Semantics(task.model).check_plan(steps(pruned[0]))


def test_a_renumbered_task_keeps_its_goal_rules(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(compact, "MIN_FACTS", 0)
    monkeypatch.setattr(compact, "MAX_USED_SHARE", 1.0)
    task = read_text(BALLS, _balls(TWO_BALLS))
    grounded = ground(task, cache=GroundingCache())
    assert isinstance(grounded.actions, compact.CompactActions)
    for engine in ENGINES:
        Semantics(task.model).check_plan(steps(plan(task, SearchOptions(engine=engine))))


@pytest.mark.parametrize("renumbered", [False, True])
def test_problems_sharing_a_structure_keep_their_own_goals(
        renumbered: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """One cache, one grounding structure (and often one action table) for problems that
    differ only in their goal: each plans for its own (the packed task, the renumbered
    table and the merged rules are kept per goal)."""
    if renumbered:
        monkeypatch.setattr(compact, "MIN_FACTS", 0)
        monkeypatch.setattr(compact, "MAX_USED_SHARE", 1.0)
    cache = GroundingCache()
    goals = [TWO_BALLS, "(or (at b0 r2) (carry b1))", TWO_BALLS.replace("r2", "r1"),
             "(exists (?x - ball) (and (carry ?x) (robot-at r2)))", "(at b0 r2)", TWO_BALLS]
    for engine in ENGINES:
        for text in goals:
            task = read_text(BALLS, _balls(text))
            result = plan(task, SearchOptions(engine=engine), cache=cache)
            assert result.status is PlanStatus.SOLVED, text
            Semantics(task.model).check_plan(steps(result))
    assert cache.hits


def test_anytime_plans_for_a_disjunctive_goal() -> None:
    task = read_text(BALLS, _balls(f"(or {TWO_BALLS} (carry b5))"))
    found = plan(task, SearchOptions(anytime=True, timeout_s=5.0))
    assert found.status is PlanStatus.SOLVED and len(found.plan) == 1
    Semantics(task.model).check_plan(steps(found))


def test_the_unified_planning_engine_solves_a_disjunctive_goal() -> None:
    problem = read_text(LIFT, lift_problem(
        "(exists (?p - passenger) (and (served ?p) (not (at ?p f0))))")).problem
    with OneshotPlanner(name="avs") as planner:
        assert planner.supports(problem.kind)
        result = planner.solve(problem)
    assert result.status in (PlanGenerationResultStatus.SOLVED_SATISFICING,
                             PlanGenerationResultStatus.SOLVED_OPTIMALLY)
    valid = SequentialPlanValidator().validate(problem, result.plan)
    assert valid.status.name == "VALID"
    unreachable = read_text(LIFT, lift_problem("(or (at p1 f2) (at p2 f2))")).problem
    with OneshotPlanner(name="avs") as planner:
        assert planner.solve(unreachable).status is \
            PlanGenerationResultStatus.UNSOLVABLE_PROVEN


def test_a_plan_of_the_engine_validates_as_ours_does() -> None:
    task = read_text(LIFT, lift_problem("(not (forall (?p - passenger) (not (served ?p))))"))
    result = plan(task, SearchOptions())
    valid = SequentialPlanValidator().validate(task.problem,
                                               to_up_plan(task.problem, result.plan))
    assert valid.status.name == "VALID"


# ---- the conjunctive path, unchanged -----------------------------------------------------

# (status, sha1 of the plan's labels, steps, expanded, generated) per instance, with
# default options, as the planner gave them before goals could be compiled to rules (the
# same in both engines)
UNCHANGED = {
    "tests/avs_planner/cp/data/briefcase": ("solved", "3103f2aa0b4b", 7, 12, 28),
    "tests/avs_planner/cp/data/axioms/psr-2": ("solved", "6d858446e476", 8, 12, 58),
    "domains/avs/problems/corridor": ("solved", "f21337916055", 9, 176, 238),
    "ipc:blocks/instance-1": ("solved", "6463a620a698", 6, 13, 27),
    "ipc:gripper/instance-1": ("solved", "7e0aae6055e7", 13, 20, 47),
    "ipc:logistics/instance-1": ("solved", "c96f0f960cd7", 20, 21, 103),
    "ipc:miconic/instance-1": ("solved", "030a9e2864c7", 4, 4, 5),
    "ipc:elevators/instance-1": ("solved", "cf3b7c813eff", 25, 54, 465),
}


def _files(key: str) -> tuple[Path, Path]:
    if key.startswith("ipc:"):
        if not IPC.is_dir():
            pytest.skip(f"IPC benchmark set not found at {IPC}")
        problem = IPC / f"{key[4:]}.pddl"
        return problem.parent / "domain.pddl", problem
    if key.startswith("domains/avs"):
        return ROOT / "domains/avs/domain.pddl", ROOT / f"{key}.pddl"
    path = ROOT / key
    domain = path.parent / f"{path.name.split('-')[0]}-domain.pddl"
    return domain, path.parent / f"{path.name}-problem.pddl"


@pytest.mark.parametrize("key", UNCHANGED)
def test_a_conjunctive_goal_plans_as_before(key: str) -> None:
    task = read_files(*_files(key))
    grounded = ground(task, cache=GroundingCache())
    assert not any(a[0].startswith(goal.GOAL_NAME) for a in grounded.facts)  # no goal rule
    for engine in ENGINES:
        result = plan(task, SearchOptions(engine=engine))
        labels = "\n".join(s.label for s in result.plan)
        assert (result.status.value, hashlib.sha1(labels.encode()).hexdigest()[:12],
                len(result.plan), result.expanded, result.generated) == UNCHANGED[key]


@pytest.mark.parametrize(("formula", "status"), [
    ("(or (served p1) (not (in p1)))", PlanStatus.SOLVED),
    ("(or (served p1) (served p2))", PlanStatus.UNSOLVABLE),
], ids=["holds", "never"])
def test_a_task_with_goal_rules_and_no_action_is_searched(formula: str,
                                                          status: PlanStatus) -> None:
    """No lift anywhere: no action applies, so the task has rules and no action (the
    native packer once failed on that)."""
    task = read_text(LIFT, lift_problem(formula).replace("(lift-at f0) ", ""))
    grounded = ground(task, cache=GroundingCache())
    assert len(grounded.actions) == 0 and grounded.axioms is not None
    for engine in ENGINES:
        result = plan(task, SearchOptions(engine=engine))
        assert result.status is status and result.plan == ()
