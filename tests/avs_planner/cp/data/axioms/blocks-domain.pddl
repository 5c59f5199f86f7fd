; Blocksworld with derived predicates (PDDL 2.2): a block is clear when nothing is on it and
; it is not held, the hand is empty when it holds nothing, and `above` is the transitive
; closure of `on`. A goal may ask for a tower's order with `above`.
(define (domain blocks-derived)
  (:requirements :strips :typing :negative-preconditions :existential-preconditions
                 :universal-preconditions :disjunctive-preconditions :derived-predicates)
  (:types block)
  (:predicates (on ?x ?y - block) (ontable ?x - block) (holding ?x - block)
               (clear ?x - block) (handempty) (above ?x ?y - block))
  (:derived (clear ?x - block)
    (and (not (holding ?x)) (not (exists (?y - block) (on ?y ?x)))))
  (:derived (handempty) (forall (?x - block) (not (holding ?x))))
  (:derived (above ?x ?y - block)
    (or (on ?x ?y) (exists (?z - block) (and (on ?x ?z) (above ?z ?y)))))
  (:action pick-up
    :parameters (?x - block)
    :precondition (and (clear ?x) (ontable ?x) (handempty))
    :effect (and (not (ontable ?x)) (holding ?x)))
  (:action put-down
    :parameters (?x - block)
    :precondition (holding ?x)
    :effect (and (not (holding ?x)) (ontable ?x)))
  (:action stack
    :parameters (?x ?y - block)
    :precondition (and (holding ?x) (clear ?y))
    :effect (and (not (holding ?x)) (on ?x ?y)))
  (:action unstack
    :parameters (?x ?y - block)
    :precondition (and (on ?x ?y) (clear ?x) (handempty))
    :effect (and (holding ?x) (not (on ?x ?y)))))
