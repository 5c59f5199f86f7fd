;; Active visual search (AVS), after Goebelbecker et al., "A planning approach to active
;; visual search in large environments", section "Domain Modeling".
;;
;; Conventions (see domains/README.md):
;;  * (probabilistic P E): with probability P the effect E happens, otherwise the action fails.
;;  * assume-* actions only set beliefs. Each defines one belief variable once (Definition 1):
;;    its precondition requires the def-flag (defined-*) to be false, its effect sets it.
;;  * (virtual ?x) marks pre-allocated objects (new-room1.., new-object1..) that an assumption
;;    instantiates; once instantiated they are ordinary rooms/objects.
;;  * p-* functions are static probabilities from the conceptual map; the rest of the numeric
;;    functions are static costs. Only total-cost changes.
(define (domain avs)
  (:requirements :strips :typing :negative-preconditions :disjunctive-preconditions
                 :universal-preconditions :equality :action-costs :probabilistic-effects)

  (:types
    place location label category relation - object
    placeholder - place
    room visualobject - location)

  (:constants in on - relation)

  (:predicates
    (at ?p - place)                          ; the robot is at place ?p
    (connected ?from - place ?to - place)    ; a known path from ?from to ?to
    (visited ?p - place)                     ; the robot has been at ?p
    (in-room ?p - place ?r - room)           ; place or placeholder ?p belongs to room ?r
    (virtual ?x - location)                  ; pre-allocated, not yet instantiated
    (has-category ?r - room ?c - category)   ; room ?r has category ?c
    (leads-to ?p - placeholder ?r - room)    ; exploring ?p leads into room ?r
    (label-of ?o - visualobject ?l - label)  ; object ?o is an instance of ?l
    (related ?o - visualobject ?rel - relation ?loc - location)  ; ?o is in/on ?loc
    (viewcones ?l - label ?rel - relation ?loc - location)       ; cones for ?l ?rel ?loc exist
    (detected ?o - visualobject)             ; ?o has been seen (a real, confirmed object)
    (reported ?l - label)                    ; the position of an ?l has been reported
    ;; def(X) flags of Definition 1: the belief variable X has been fixed
    (defined-leads-to ?p - placeholder)
    (defined-category ?r - room)
    (defined-exists ?l - label ?rel - relation ?loc - location))

  (:functions
    (total-cost) - number
    (move-cost ?from - place ?to - place) - number      ; path length, static
    (search-cost ?l - label ?rel - relation) - number   ; expected DT search effort, static
    (p-room-category ?r - room ?c - category) - number            ; P_category(room)
    (p-placeholder-category ?p - placeholder ?c - category) - number  ; P_category(placeholder)
    (p-obj-in ?l - label ?r - room ?c - category) - number  ; P(ObjectAt L), L = in room ?r
    (p-obj-on ?l - label ?s - label ?c - category) - number ; P(ObjectAt L^C), on an ?s in a ?c
    (p-detect ?l - label ?rel - relation) - number          ; 1 - false-negative rate
    ;; P(a search on ?s finds the ?l assumed on it): the detection rate times the share of
    ;; ?l on this very ?s that earlier looks at it would have missed (1 before any look)
    (p-find-on ?l - label ?s - visualobject) - number)

  ;; ---- assumptive actions: never executed, only monitored -------------------------------

  (:action assume-leads-to-room
    :parameters (?p - placeholder ?c - category ?r - room)
    :precondition (and (virtual ?r) (not (defined-leads-to ?p)))
    :effect (probabilistic (p-placeholder-category ?p ?c)
              (and (not (virtual ?r)) (leads-to ?p ?r) (in-room ?p ?r) (has-category ?r ?c)
                   (defined-leads-to ?p) (defined-category ?r))))

  (:action assume-category
    :parameters (?r - room ?c - category)
    :precondition (and (not (virtual ?r)) (not (defined-category ?r)))
    :effect (probabilistic (p-room-category ?r ?c)
              (and (has-category ?r ?c) (defined-category ?r))))

  (:action assume-obj-exists-in
    :parameters (?l - label ?r - room ?c - category ?o - visualobject)
    :precondition (and (has-category ?r ?c) (virtual ?o) (not (defined-exists ?l in ?r)))
    :effect (probabilistic (p-obj-in ?l ?r ?c)
              (and (not (virtual ?o)) (label-of ?o ?l) (related ?o in ?r)
                   (defined-exists ?l in ?r))))

  ;; (not (= ?o ?s)): an object is not assumed on itself. A virtual support that an assumption
  ;; gave a label is no longer virtual, so no plan uses these groundings; ruling them out in
  ;; the domain keeps them out of the relaxed heuristics too (15% of the ground actions of a
  ;; 20-place problem, planning 15-30% faster, same plans).
  (:action assume-obj-exists-on
    :parameters (?l - label ?s - visualobject ?sl - label ?c - category ?r - room
                 ?o - visualobject)
    :precondition (and (label-of ?s ?sl) (related ?s in ?r) (has-category ?r ?c) (virtual ?o)
                       (not (= ?o ?s)) (not (defined-exists ?l on ?s)))
    :effect (probabilistic (p-obj-on ?l ?sl ?c)
              (and (not (virtual ?o)) (label-of ?o ?l) (related ?o on ?s)
                   (defined-exists ?l on ?s))))

  ;; ---- physical and sensing actions ---------------------------------------------------

  (:action move
    :parameters (?from - place ?to - place)
    :precondition (and (at ?from) (connected ?from ?to))
    :effect (and (not (at ?from)) (at ?to) (visited ?to)
                 (increase (total-cost) (move-cost ?from ?to))))

  ;; View cones for a room need the room fully explored: every placeholder in it visited.
  (:action createviewcones-in
    :parameters (?l - label ?r - room)
    :precondition (and (not (virtual ?r))
                       (forall (?q - placeholder) (imply (in-room ?q ?r) (visited ?q))))
    :effect (and (viewcones ?l in ?r) (increase (total-cost) 1)))

  (:action createviewcones-on
    :parameters (?l - label ?s - visualobject)
    :precondition (detected ?s)
    :effect (and (viewcones ?l on ?s) (increase (total-cost) 1)))

  ;; SEARCHFOROBJECT hands control to the DT planner, which starts from the robot's place ?p.
  (:action searchforobject-in
    :parameters (?l - label ?r - room ?o - visualobject ?p - place)
    :precondition (and (viewcones ?l in ?r) (label-of ?o ?l) (related ?o in ?r)
                       (not (detected ?o)) (at ?p) (in-room ?p ?r))
    :effect (and (probabilistic (p-detect ?l in) (detected ?o))
                 (increase (total-cost) (search-cost ?l in))))

  (:action searchforobject-on
    :parameters (?l - label ?s - visualobject ?o - visualobject ?r - room ?p - place)
    :precondition (and (viewcones ?l on ?s) (label-of ?o ?l) (related ?o on ?s)
                       (not (detected ?o)) (related ?s in ?r) (at ?p) (in-room ?p ?r))
    :effect (and (probabilistic (p-find-on ?l ?s) (detected ?o))
                 (increase (total-cost) (search-cost ?l on))))

  (:action reportposition
    :parameters (?o - visualobject ?l - label)
    :precondition (and (detected ?o) (label-of ?o ?l))
    :effect (and (reported ?l) (increase (total-cost) 1))))
