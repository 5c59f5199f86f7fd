"""What a state settles for good (`settled.py`): which fluents are limited, which true atoms are
pinned and which probability atoms are zero (both key the cached structure), that the join
leaves out what they rule out, and that the ground task and plan are the same as without them
on every kind of problem."""

from __future__ import annotations

import pytest

from avs_planner.cp import grounding
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import SearchOptions
from avs_planner.cp.settled import NOTHING_SETTLED, settled_atoms
from avs_planner.cp.task import WorldState
from avs_planner.errors import PlanningError
from avs_planner.pddl import read_files, read_text
from avs_planner.pddl.model import ProbabilisticProblem
from bench.avs_generator import AvsSize, generate

from .conftest import AVS_DOMAIN, avs_and_ipc_makers, random_problem
from .test_cp_structure_compiled import STATICS_DOMAIN, STATICS_PROBLEM


def _settled(pproblem: ProbabilisticProblem):
    cache = GroundingCache()
    return settled_atoms(pproblem.problem, cache.schemas(pproblem), cache._keys(pproblem)[1])


def _statics() -> ProbabilisticProblem:
    return read_text(STATICS_DOMAIN, STATICS_PROBLEM, "d.pddl", "p.pddl")


def test_a_fluent_added_for_a_subtype_only_is_limited():
    pproblem = _statics()
    limits = _settled(pproblem)
    # cook adds (base ?k) for kitchens; at and visited are added for every place and robot
    assert set(limits.adds) == {"base"}
    assert limits.addable(("base", "k1"))
    assert not limits.addable(("base", "p1"))
    assert limits.addable(("at", "r1", "p1"))  # not limited: anything may be added
    state = GroundingCache().initial_state(pproblem)
    assert limits.pinned(state.true_atoms) == {("base", "p3")}


def test_avs_domain_limits_in_room_and_virtual():
    pproblem = read_files(AVS_DOMAIN, AVS_DOMAIN.parent / "problems" / "corridor.pddl")
    limits = _settled(pproblem)
    assert {"in-room", "virtual"} <= set(limits.adds)
    assert "at" not in limits.adds and "visited" not in limits.adds
    assert limits.adds["virtual"] == ()  # only ever deleted
    assert not limits.addable(("in-room", "place0", "room1"))  # ordinary places: never added
    assert limits.addable(("in-room", "place1", "room1"))  # a placeholder: an assumption may


def test_pinned_atoms_key_the_structure_and_addable_ones_do_not():
    pproblem = _statics()
    cache = GroundingCache()
    state = cache.initial_state(pproblem)
    first = cache.structure(pproblem, state)
    # a kitchen's base may be added by cook: the same structure serves both states
    with_kitchen = WorldState(state.true_atoms | {("base", "k1")}, state.values)
    assert cache.structure(pproblem, with_kitchen) is first
    # an ordinary place's base can only be true from the start: another structure, which
    # grounds the actions it allows
    with_p1 = WorldState(state.true_atoms | {("base", "p1")}, state.values)
    other = cache.structure(pproblem, with_p1)
    assert other is not first
    labels = {other.label(r) for r in range(other.size)}
    assert "(stay r1 p1 p1)" in labels
    assert "(stay r1 p1 p1)" not in {first.label(r) for r in range(first.size)}


def test_a_pinned_atom_that_is_deleted_still_counts():
    """A limited atom true at the start may be deleted; plans that need it first are found."""
    domain = """
    (define (domain once)
      (:requirements :strips :typing)
      (:types thing)
      (:predicates (fresh ?t - thing) (used ?t - thing))
      (:action use :parameters (?t - thing)
        :precondition (fresh ?t) :effect (and (used ?t) (not (fresh ?t)))))
    """
    problem = """
    (define (problem once1) (:domain once)
      (:objects a b c - thing)
      (:init (fresh a) (fresh c))
      (:goal (and (used a) (used c))))
    """
    pproblem = read_text(domain, problem, "d.pddl", "p.pddl")
    result = plan(pproblem, SearchOptions(weight=1.0, heuristic="hmax"), cache=GroundingCache())
    assert result.solved
    assert sorted(step.label for step in result.plan) == ["(use a)", "(use c)"]
    task = ground(pproblem, cache=GroundingCache())
    assert sorted(a.label for a in task.actions) == ["(use a)", "(use c)"]  # never b


ODDS_DOMAIN = """
(define (domain odds)
  (:requirements :strips :typing :numeric-fluents :action-costs :probabilistic-effects)
  (:types thing)
  (:predicates (have ?t - thing))
  (:functions (total-cost) - number (chance ?t - thing) - number)
  (:action get :parameters (?t - thing)
    :effect (probabilistic (chance ?t) (have ?t))))
"""


def _odds_problem(chances: dict[str, str], goal: str = "(have a)") -> ProbabilisticProblem:
    values = " ".join(f"(= (chance {t}) {v})" for t, v in chances.items())
    problem = f"""
    (define (problem odds1) (:domain odds)
      (:objects a b c - thing)
      (:init {values})
      (:goal {goal}))
    """
    return read_text(ODDS_DOMAIN, problem, "d.pddl", "p.pddl")


def test_actions_that_never_succeed_are_not_ground():
    pproblem = _odds_problem({"a": "0.5", "b": "0", "c": "1"})
    settled = _settled(pproblem)
    assert settled.odds == {"get": ("chance", "?t")}
    cache = GroundingCache()
    state = cache.initial_state(pproblem)
    assert settled.key(state) == (frozenset(), frozenset({("chance", "b")}))
    st = cache.structure(pproblem, state)
    assert {st.label(r) for r in range(st.size)} == {"(get a)", "(get c)"}
    # other zeros: another structure; other non-zero values: the same one
    assert cache.structure(pproblem, WorldState(state.true_atoms, {
        **state.values, ("chance", "b"): 0.25})) is not st
    assert cache.structure(pproblem, WorldState(state.true_atoms, {
        **state.values, ("chance", "a"): 0.75})) is st


def test_a_goal_only_a_zero_chance_action_reaches_is_unsolvable():
    pproblem = _odds_problem({"a": "0", "b": "0.5", "c": "1"})
    result = plan(pproblem, SearchOptions(), cache=GroundingCache())
    assert result.status.value == "unsolvable"


def test_a_missing_probability_is_still_named():
    """(The reader rejects such a problem; a state built by a caller may still lack one.)"""
    pproblem = _odds_problem({"a": "0.5", "b": "0", "c": "1"})
    cache = GroundingCache()
    state = cache.initial_state(pproblem)
    values = {k: v for k, v in state.values.items() if k != ("chance", "a")}
    with pytest.raises(PlanningError, match=r"chance a"):
        ground(pproblem, WorldState(state.true_atoms, values), cache=cache)


def _cases() -> list[tuple[str, object]]:
    avs = AVS_DOMAIN.read_text()
    cases: list[tuple[str, object]] = [
        ("statics", _statics),
        ("odds", lambda: _odds_problem({"a": "0.5", "b": "0", "c": "1"},
                                       "(and (have a) (have c))")),
    ]
    for seed in (0, 1):
        cases.append((f"gen-s{seed}", lambda s=seed: read_text(
            avs, generate(AvsSize(8, 2, 2, 4), s), "d.pddl", "p.pddl")))
    for seed in range(3):
        cases.append((f"random-{seed}", lambda s=seed: random_problem(s, 6, 8)))
    return cases + avs_and_ipc_makers()


@pytest.mark.parametrize(("name", "make"), _cases(), ids=[n for n, _ in _cases()])
def test_same_actions_and_plan_as_without_limits(name, make, monkeypatch):
    """The join only leaves out what the reachability pass and the probability check
    dropped anyway."""
    pproblem = make()
    # a node limit, not only the timeout, ends the searches that find nothing (barman at
    # w = 2): the counts compared must not depend on the machine's speed
    options = SearchOptions(timeout_s=30.0, node_limit=20_000)
    limited_task = ground(pproblem, cache=GroundingCache())
    limited = plan(pproblem, options, cache=GroundingCache())
    with monkeypatch.context() as m:
        m.setattr(grounding, "settled_atoms", lambda *args: NOTHING_SETTLED)
        full_task = ground(pproblem, cache=GroundingCache())
        full = plan(pproblem, options, cache=GroundingCache())
    assert [a.label for a in limited_task.actions] == [a.label for a in full_task.actions]
    assert set(limited_task.facts) <= set(full_task.facts)
    assert limited.status == full.status
    assert [s.label for s in limited.plan] == [s.label for s in full.plan]
    assert (limited.cost, limited.objective, limited.expanded) == (
        full.cost, full.objective, full.expanded)


NEVER_UNDONE_DOMAIN = """(define (domain chores)
  (:requirements :strips :typing :negative-preconditions)
  (:types job)
  (:predicates (done ?j - job) (ready ?j - job) (paid))
  (:action work :parameters (?j - job) :precondition (and (ready ?j) (not (done ?j)))
    :effect (and (done ?j) (not (ready ?j))))
  (:action collect :parameters (?j - job) :precondition (done ?j) :effect (paid)))"""

NEVER_UNDONE_PROBLEM = """(define (problem p) (:domain chores)
  (:objects a b - job)
  (:init (done a) (ready a) (ready b))
  (:goal (paid)))"""


def test_an_action_needing_false_an_atom_true_for_good_is_not_grounded():
    """`(done a)` is true and no action deletes it: `work a` can never apply, so it is left
    out of the ground task (the delete relaxation would otherwise count it); `work b` and a
    negative precondition on an atom some action deletes (`ready`) are kept."""
    task = ground(read_text(NEVER_UNDONE_DOMAIN, NEVER_UNDONE_PROBLEM, "d.pddl", "p.pddl"))
    assert task.action("work", ("a",)) is None
    assert task.action("work", ("b",)) is not None
    assert task.action("collect", ("a",)) is not None
    with_undo = NEVER_UNDONE_DOMAIN.replace(
        "(:action collect", "(:action undo :parameters (?j - job) :precondition (paid)\n"
        "    :effect (not (done ?j)))\n  (:action collect")
    task = ground(read_text(with_undo, NEVER_UNDONE_PROBLEM, "d.pddl", "p.pddl"))
    assert task.action("work", ("a",)) is not None
