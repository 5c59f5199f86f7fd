"""PDDL texts shared by the planner tests."""

from __future__ import annotations


def lamps(count: int) -> tuple[str, str]:
    """A `flip` whose effects hold one state-dependent condition per lamp."""
    domain = """(define (domain lamps)
  (:requirements :strips :typing :conditional-effects)
  (:types lamp)
  (:predicates (on ?l - lamp) (lit ?l - lamp) (done))
  (:action switch :parameters (?l - lamp) :effect (on ?l))
  (:action flip :parameters ()
    :effect (and (done) (forall (?l - lamp) (when (on ?l) (lit ?l))))))
"""
    objects = " ".join(f"o{i}" for i in range(count))
    problem = f"""(define (problem many) (:domain lamps)
  (:objects {objects} - lamp)
  (:init (on o0))
  (:goal (done)))
"""
    return domain, problem


LIFT = """(define (domain lift)
  (:requirements :strips :typing :universal-preconditions :disjunctive-preconditions
                 :existential-preconditions :negative-preconditions)
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


def lift_problem(goal: str) -> str:
    """Two passengers and three floors of `LIFT`, with this goal."""
    return f"""(define (problem two) (:domain lift)
  (:objects p1 p2 - passenger f0 f1 f2 - floor)
  (:init (lift-at f0) (at p1 f0) (at p2 f1) (dest p1 f2) (dest p2 f0))
  (:goal {goal}))
"""
