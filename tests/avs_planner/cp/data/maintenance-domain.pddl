; The IPC maintenance scheduling domain (IPC 2014): mechanics work at one airport a day;
; a plane at that airport on that day gets its maintenance (a conditional effect).
(define (domain maintenance-scheduling-domain)
 (:requirements :adl :typing :conditional-effects)
 (:types plane day airport)
 (:predicates (done ?p - plane)
  (today ?d - day)
  (at ?p - plane ?d - day ?c - airport)
  (next ?d - day ?d2 - day))

 (:action workat
  :parameters (?day - day ?airport - airport)
  :precondition (today ?day)
  :effect (and
     (not (today ?day))
     (forall (?plane - plane) (when (at ?plane ?day ?airport) (done ?plane))))))
