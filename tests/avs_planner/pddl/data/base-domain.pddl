; A small valid domain that the broken-input and property tests mutate.
(define (domain shelf)
  (:requirements :strips :typing :negative-preconditions :action-costs
                 :probabilistic-effects)
  (:types block table - object)
  (:constants floor - table)
  (:predicates (on ?x - block ?t - table) (clear ?x - block) (holding ?x - block))
  (:functions (total-cost) - number
              (p-grip ?x - block) - number
              (lift-cost ?x - block) - number)
  (:action pick
    :parameters (?x - block ?t - table)
    :precondition (and (on ?x ?t) (clear ?x) (not (holding ?x)))
    :effect (and (probabilistic (p-grip ?x) (and (holding ?x) (not (on ?x ?t))))
                 (increase (total-cost) (lift-cost ?x))))
  (:action place
    :parameters (?x - block ?t - table)
    :precondition (holding ?x)
    :effect (and (probabilistic 9/10 (and (on ?x ?t) (not (holding ?x))))
                 (increase (total-cost) 1))))
