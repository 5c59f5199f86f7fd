; Valid PDDL with upper case, empty precondition, equality, numeric conditions and metric.
(define (domain Edge)
  (:requirements :STRIPS :typing :equality :numeric-fluents :negative-preconditions)
  (:types thing)
  (:predicates (P ?x - thing) (Q ?x - thing ?y - thing))
  (:functions (f ?x - thing) (total-cost))
  (:action Noop
    :parameters ()
    :precondition ()
    :effect (and))
  (:action Go
    :parameters (?x - thing ?y - thing)
    :precondition (and (not (= ?x ?y)) (> (f ?x) 0) (P ?x))
    :effect (and (Q ?x ?y) (decrease (f ?x) 1) (increase (total-cost) (f ?y)))))
