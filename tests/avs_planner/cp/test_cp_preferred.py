"""Helpful actions (preferred operators) and p = 0 pruning in grounding."""

from __future__ import annotations

from avs_planner.cp.grounding import ground
from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.planner import plan
from avs_planner.cp.search import SearchOptions


def test_ff_helpful_actions_are_applicable_relaxed_plan_actions(corridor):
    task = ground(corridor)
    estimator = get_heuristic("ff").factory(task, 500.0)
    hc, _ = estimator(task.init)
    helpful = estimator.helpful[task.init]
    assert helpful and hc > 0
    for i in helpful:
        assert task.actions[i].applicable(task.init)
    names = {task.actions[i].name for i in helpful}
    assert "move" in names or any(n.startswith("assume") for n in names)


def test_preferred_queue_keeps_the_plan_quality(corridor, make_random):
    for pproblem in [corridor] + [make_random(seed) for seed in range(20)]:
        on = plan(pproblem, SearchOptions(weight=2.0, preferred=True))
        off = plan(pproblem, SearchOptions(weight=2.0, preferred=False))
        assert on.status == off.status
        if on.solved:
            assert on.objective <= off.objective + 1e-9


def test_grounding_drops_actions_that_never_succeed(corridor):
    task = ground(corridor)
    assert task.actions
    assert all(a.probability > 0.0 for a in task.actions)
    assert [a.index for a in task.actions] == list(range(len(task.actions)))


FORALL_DOMAIN = """(define (domain tour)
  (:requirements :strips :typing :negative-preconditions :disjunctive-preconditions
                 :universal-preconditions :action-costs)
  (:types spot)
  (:predicates (marked ?s - spot) (visited ?s - spot) (seen ?s - spot) (done))
  (:functions (total-cost) - number)
  (:action unmark :parameters (?s - spot) :precondition (marked ?s)
    :effect (and (not (marked ?s)) (increase (total-cost) 100)))
  (:action visit :parameters (?s - spot) :precondition (not (visited ?s))
    :effect (and (visited ?s) (seen ?s) (increase (total-cost) 5)))
  (:action finish :parameters ()
    :precondition (forall (?s - spot) (imply (marked ?s) (visited ?s)))
    :effect (and (done) (increase (total-cost) 1))))
"""

FORALL_PROBLEM = """(define (problem tour3) (:domain tour)
  (:objects a b c - spot)
  (:init (marked a) (marked b) (= (total-cost) 0))
  (:goal (done)) (:metric minimize (total-cost)))
"""


def test_inadmissible_estimates_count_forall_imply_clauses_and_hmax_stays_admissible():
    from avs_planner.pddl import read_text

    pproblem = read_text(FORALL_DOMAIN, FORALL_PROBLEM, "tour.pddl", "tour3.pddl")
    task = ground(pproblem)
    hadd_c, _ = get_heuristic("hadd").factory(task, 500.0)(task.init)
    ff_c, _ = get_heuristic("ff").factory(task, 500.0)(task.init)
    hmax_c, _ = get_heuristic("hmax").factory(task, 500.0)(task.init)
    assert hadd_c == 5 + 5 + 1  # visit a, visit b (c is not marked), finish
    assert ff_c == (5 + 1) + (5 + 1) + (1 + 1)  # FF counts +1 per action
    optimal = plan(pproblem, SearchOptions(weight=1.0, heuristic="hmax"))
    assert optimal.solved and hmax_c <= optimal.cost == 11


def test_effects_on_facts_nothing_reads_are_dropped():
    from avs_planner.pddl import read_text

    task = ground(read_text(FORALL_DOMAIN, FORALL_PROBLEM, "tour.pddl", "tour3.pddl"))
    seen = task.fact_index[("seen", "a")]
    visited = task.fact_index[("visited", "a")]
    visit = task.action("visit", ["a"])
    assert visit is not None
    assert not visit.add >> seen & 1 and visit.add >> visited & 1
    assert seen not in visit.add_facts
