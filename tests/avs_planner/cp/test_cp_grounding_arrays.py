"""The array grounder: joins over static atoms, typing, constants, (in)equality, the array
form of the task, and errors for bad numeric values. Expected ground actions are written out
by hand or enumerated naively with itertools over the objects."""

from __future__ import annotations

import itertools

import pytest

from avs_planner.cp.encoding import AtomSpace
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus
from avs_planner.errors import PlanningError
from avs_planner.pddl import read_text

DOMAIN = """
(define (domain shapes)
  (:requirements :strips :typing :negative-preconditions :equality :action-costs)
  (:types box ball - thing  thing room)
  (:constants red - ball)
  (:predicates (in ?t - thing ?r - room) (door ?a - room ?b - room) (locked ?r - room)
               (held ?t - thing) (free) (marked ?b - ball))
  (:functions (total-cost) - number (weight ?t - thing) - number)
  (:action carry
    :parameters (?t - thing ?from - room ?to - room)
    :precondition (and (door ?from ?to) (not (locked ?to)) (in ?t ?from) (not (= ?from ?to)))
    :effect (and (not (in ?t ?from)) (in ?t ?to) (increase (total-cost) (weight ?t))))
  (:action mark-red
    :parameters (?r - room)
    :precondition (and (in red ?r))
    :effect (marked red))
  (:action pick
    :parameters (?a - thing ?b - thing)
    :precondition (and (= ?a ?b) (free))
    :effect (and (held ?a) (not (free))))
  (:action reset
    :parameters ()
    :precondition (not (free))
    :effect (free)))
"""

PROBLEM = """
(define (problem p) (:domain shapes)
  (:objects b1 b2 - box g1 - ball k1 k2 k3 - room)
  (:init (door k1 k2) (door k2 k1) (door k2 k3) (door k3 k3) (locked k3)
         (in b1 k1) (in g1 k2) (in red k1) (free)
         (= (weight b1) 2) (= (weight b2) 3) (= (weight g1) 1) (= (weight red) 4)
         (= (total-cost) 0))
  (:goal (and (in b1 k2) (marked red) (held g1)))
  (:metric minimize (total-cost)))
"""


@pytest.fixture(scope="module")
def shapes():
    return read_text(DOMAIN, PROBLEM, "shapes.pddl", "p.pddl")


def test_static_join_typing_and_inequality(shapes):
    task = ground(shapes, cache=GroundingCache())
    carries = {a.args for a in task.actions if a.name == "carry"}
    things = ["b1", "b2", "g1", "red"]
    doors = {("k1", "k2"), ("k2", "k1"), ("k2", "k3"), ("k3", "k3")}
    locked = {"k3"}
    # naive enumeration of what the statics allow; reachability and relevance then prune
    allowed = {(t, a, b) for t, (a, b) in itertools.product(things, doors)
               if b not in locked and a != b}
    assert carries <= allowed
    assert ("b1", "k1", "k2") in carries  # needed for the goal
    assert not any(b == "k3" for _, _, b in carries)  # locked (a static negative condition)
    assert task.action("carry", ["b1", "k1", "k2"]).cost == 2  # weight b1


def test_constants_equality_and_zero_parameter_actions(shapes):
    task = ground(shapes, cache=GroundingCache())
    # red (a constant) starts in k1 and can be carried to k2, never into locked k3
    assert {a.args for a in task.actions if a.name == "mark-red"} == {("k1",), ("k2",)}
    picks = {a.args for a in task.actions if a.name == "pick"}
    assert picks and all(a == b for a, b in picks)
    assert task.action("pick", ["g1", "g1"]) is not None
    assert task.action("pick", ["g1", "b1"]) is None
    # `reset` has no parameters; it is needed to pick again after (free) was deleted
    assert all(a.args == () for a in task.actions if a.name == "reset")


def test_array_form_matches_the_actions(shapes, corridor):
    for pproblem in (shapes, corridor):
        task = ground(pproblem, cache=GroundingCache())
        arrays = task.arrays
        assert len(arrays.pre) == len(task.actions)
        for i, action in enumerate(task.actions):
            for matrix, mask in ((arrays.pre, action.pre), (arrays.pre_neg, action.pre_neg),
                                 (arrays.add, action.add), (arrays.delete, action.delete)):
                ids = [f for f in matrix[i].tolist() if f >= 0]
                assert ids == sorted(set(ids))
                assert sum(1 << f for f in ids) == mask
            assert tuple(f for f in arrays.pre[i].tolist() if f >= 0) == action.pre_facts
            assert arrays.cost[i] == action.cost
            assert arrays.probability[i] == action.probability


def test_atom_codes_round_trip(shapes):
    space = AtomSpace(shapes.problem)
    atoms = [("in", "b1", "k3"), ("door", "k2", "k1"), ("free",), ("marked", "red"),
             ("weight", "g1")]
    codes = [space.encode(a) for a in atoms]
    assert len(set(codes)) == len(codes)
    assert [space.decode(c) for c in codes] == atoms
    assert space.encode(("marked", "b1")) is None  # b1 is a box, not a ball
    assert space.encode(("in", "nowhere", "k1")) is None


def test_bad_numeric_values_name_the_action(shapes):
    text = PROBLEM.replace("(= (weight b1) 2)", "(= (weight b1) -2)")
    with pytest.raises(PlanningError, match=r"cost of \(carry b1 k1 k2\) is -2"):
        ground(read_text(DOMAIN, text, "shapes.pddl", "p.pddl"), cache=GroundingCache())
    missing = PROBLEM.replace("(= (weight b1) 2)", "")
    with pytest.raises(PlanningError, match=r"no value for \(weight b1\)"):
        ground(read_text(DOMAIN, missing, "shapes.pddl", "p.pddl"), cache=GroundingCache())


def test_a_goal_no_action_touches_is_decided_by_the_initial_state():
    domain = """(define (domain d) (:requirements :strips :typing) (:types t)
      (:predicates (p ?x - t) (q))
      (:action a :parameters (?x - t) :precondition (p ?x) :effect (q)))"""
    holds = "(define (problem h) (:domain d) (:objects o - t) (:init (q)) (:goal (q)))"
    fails = "(define (problem f) (:domain d) (:objects o - t) (:init) (:goal (q)))"
    # (p o) is static and false, so no ground action mentions (q): the initial state decides
    solved = plan(read_text(domain, holds, "d.pddl", "h.pddl"), cache=GroundingCache())
    assert solved.status is PlanStatus.SOLVED and solved.plan == ()
    unsolvable = plan(read_text(domain, fails, "d.pddl", "f.pddl"), cache=GroundingCache())
    assert unsolvable.status is PlanStatus.UNSOLVABLE


def test_static_fluent_names_match_up(shapes, corridor):
    from unified_planning.io import PDDLReader

    from avs_planner.cp.grounding import static_fluent_names
    from tests.ipc import IPC, domain_for

    problems = [shapes.problem, corridor.problem]
    for domain in ("blocks", "elevators", "logistics", "gripper", "airport", "openstacks",
                   "trucks"):
        if (IPC / domain).is_dir():
            instance = IPC / domain / "instance-1.pddl"
            problems.append(PDDLReader().parse_problem(str(domain_for(instance)), str(instance)))
    for problem in problems:
        expected = frozenset(f.name for f in problem.get_static_fluents())
        assert static_fluent_names(problem) == expected
    assert "door" in static_fluent_names(shapes.problem)
    assert "in" not in static_fluent_names(shapes.problem)
