; A small power supply restoration domain in the style of IPC 2004's PSR: power flows from
; closed breakers through closed devices (`fed`, recursive), the network is safe when no
; faulty line is fed (a negation of `fed`, one stratum up). Closing a breaker needs a safe
; network; closing a switch while the network is unsafe trips the protection (a conditional
; effect on a derived condition), which only a reset in a safe network clears.
(define (domain mini-psr)
  (:requirements :strips :typing :negative-preconditions :disjunctive-preconditions :equality
                 :existential-preconditions :conditional-effects :derived-predicates)
  (:types device - object  breaker switch line - device)
  (:predicates (closed ?d - device) (con ?x ?y - device) (faulty ?l - line)
               (fed ?d - device) (safe) (tripped))
  (:derived (fed ?d - device)
    (or (exists (?b - breaker) (and (= ?b ?d) (closed ?b)))
        (exists (?e - device) (and (fed ?e) (closed ?e) (con ?e ?d)))))
  (:derived (safe) (not (exists (?l - line) (and (faulty ?l) (fed ?l)))))
  (:action close-switch
    :parameters (?s - switch)
    :precondition (not (closed ?s))
    :effect (and (closed ?s) (when (not (safe)) (tripped))))
  (:action open-switch
    :parameters (?s - switch)
    :precondition (closed ?s)
    :effect (not (closed ?s)))
  (:action close-breaker
    :parameters (?b - breaker)
    :precondition (and (not (closed ?b)) (safe) (not (tripped)))
    :effect (closed ?b))
  (:action reset
    :parameters ()
    :precondition (and (tripped) (safe))
    :effect (not (tripped))))
