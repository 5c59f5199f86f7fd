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
