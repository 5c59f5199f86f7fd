(define (domain briefcase)
  (:requirements :typing :conditional-effects :negative-preconditions :equality)
  (:types place thing)
  (:predicates (at-case ?p - place) (at ?t - thing ?p - place) (in ?t - thing) (locked))
  (:action move
    :parameters (?from ?to - place)
    :precondition (and (at-case ?from) (not (= ?from ?to)))
    :effect (and (not (at-case ?from)) (at-case ?to)
                 (forall (?t - thing)
                   (when (and (in ?t) (not (locked))) (and (not (at ?t ?from)) (at ?t ?to))))))
  (:action put-in
    :parameters (?t - thing ?p - place)
    :precondition (and (at ?t ?p) (at-case ?p))
    :effect (in ?t))
  (:action take-out
    :parameters (?t - thing)
    :precondition (in ?t)
    :effect (not (in ?t)))
  (:action toggle-lock
    :parameters ()
    :effect (and (when (locked) (not (locked))) (when (not (locked)) (locked)))))
