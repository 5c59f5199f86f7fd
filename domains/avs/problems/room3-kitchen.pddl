;; Goebelbecker et al., "A Planning Approach to Active Visual Search in Large Environments",
;; section 4, second plan: the robot explored the corridor (room1), found office1
;; (room2, an office) and then room3, which is probably a kitchen (0.8). room3 is not fully
;; explored: its placeholder place16 is still to be visited. The corridor's far end
;; (placeholder place20) is unexplored. Target: a cerealbox. Expected best plan (R = 500):
;;   assume-category room3 kitchen
;;   assume-obj-exists-in table room3 kitchen new-object1
;;   assume-obj-exists-on cerealbox new-object1 table kitchen room3 new-object2
;;   move place10 place18, move place18 place16, createviewcones-in table room3,
;;   searchforobject-in table room3 new-object1 place16, createviewcones-on cerealbox new-object1,
;;   searchforobject-on cerealbox new-object1 new-object2 room3 place16,
;;   reportposition new-object2 cerealbox
(define (problem room3-kitchen)
  (:domain avs)
  (:objects
    place10 place12 place18 - place
    place16 place20 - placeholder
    room1 room2 room3 new-room1 new-room2 - room
    new-object1 new-object2 new-object3 - visualobject
    cerealbox table - label
    kitchen office corridor - category)
  (:init
    (at place10) (visited place10) (visited place12) (visited place18)
    (connected place10 place12) (connected place12 place10)
    (connected place12 place20) (connected place20 place12)
    (connected place10 place18) (connected place18 place10)
    (connected place18 place16) (connected place16 place18)
    (in-room place10 room1) (in-room place12 room1) (in-room place20 room1)
    (in-room place18 room3) (in-room place16 room3)
    (has-category room1 corridor) (defined-category room1)
    (has-category room2 office) (defined-category room2)
    (virtual new-room1) (virtual new-room2)
    (virtual new-object1) (virtual new-object2) (virtual new-object3)
    (= (total-cost) 0)
    ;; path lengths in metres (0 where there is no path)
    (= (move-cost place10 place10) 0) (= (move-cost place10 place12) 4) (= (move-cost place10 place16) 0) (= (move-cost place10 place18) 3) (= (move-cost place10 place20) 0)
    (= (move-cost place12 place10) 4) (= (move-cost place12 place12) 0) (= (move-cost place12 place16) 0) (= (move-cost place12 place18) 0) (= (move-cost place12 place20) 6)
    (= (move-cost place16 place10) 0) (= (move-cost place16 place12) 0) (= (move-cost place16 place16) 0) (= (move-cost place16 place18) 3) (= (move-cost place16 place20) 0)
    (= (move-cost place18 place10) 3) (= (move-cost place18 place12) 0) (= (move-cost place18 place16) 3) (= (move-cost place18 place18) 0) (= (move-cost place18 place20) 0)
    (= (move-cost place20 place10) 0) (= (move-cost place20 place12) 6) (= (move-cost place20 place16) 0) (= (move-cost place20 place18) 0) (= (move-cost place20 place20) 0)
    (= (search-cost table in) 40) (= (search-cost table on) 10)
    (= (search-cost cerealbox in) 120) (= (search-cost cerealbox on) 10)
    (= (p-detect table in) 0.8) (= (p-detect table on) 0.8)
    (= (p-detect cerealbox in) 0.5) (= (p-detect cerealbox on) 0.8)
    (= (p-find-on table new-object1) 0.8) (= (p-find-on table new-object2) 0.8) (= (p-find-on table new-object3) 0.8)
    (= (p-find-on cerealbox new-object1) 0.8) (= (p-find-on cerealbox new-object2) 0.8) (= (p-find-on cerealbox new-object3) 0.8)
    ;; P_category(room)
    (= (p-room-category room1 kitchen) 0) (= (p-room-category room1 office) 0) (= (p-room-category room1 corridor) 1)
    (= (p-room-category room2 kitchen) 0) (= (p-room-category room2 office) 1) (= (p-room-category room2 corridor) 0)
    (= (p-room-category room3 kitchen) 0.8) (= (p-room-category room3 office) 0.15) (= (p-room-category room3 corridor) 0.05)
    (= (p-room-category new-room1 kitchen) 0) (= (p-room-category new-room1 office) 0) (= (p-room-category new-room1 corridor) 0)
    (= (p-room-category new-room2 kitchen) 0) (= (p-room-category new-room2 office) 0) (= (p-room-category new-room2 corridor) 0)
    ;; P_category(placeholder)
    (= (p-placeholder-category place16 kitchen) 0) (= (p-placeholder-category place16 office) 0) (= (p-placeholder-category place16 corridor) 0)
    (= (p-placeholder-category place20 kitchen) 0.2) (= (p-placeholder-category place20 office) 0.5) (= (p-placeholder-category place20 corridor) 0.1)
    ;; P(ObjectAt L) for rooms; unexplored (virtual) rooms get the category defaults
    (= (p-obj-in cerealbox room1 kitchen) 0.6) (= (p-obj-in cerealbox room1 office) 0.1) (= (p-obj-in cerealbox room1 corridor) 0.02)
    (= (p-obj-in table room1 kitchen) 0.9) (= (p-obj-in table room1 office) 0.7) (= (p-obj-in table room1 corridor) 0.1)
    (= (p-obj-in cerealbox room2 kitchen) 0.6) (= (p-obj-in cerealbox room2 office) 0.1) (= (p-obj-in cerealbox room2 corridor) 0.02)
    (= (p-obj-in table room2 kitchen) 0.9) (= (p-obj-in table room2 office) 0.7) (= (p-obj-in table room2 corridor) 0.1)
    (= (p-obj-in cerealbox room3 kitchen) 0.6) (= (p-obj-in cerealbox room3 office) 0.1) (= (p-obj-in cerealbox room3 corridor) 0.02)
    (= (p-obj-in table room3 kitchen) 0.9) (= (p-obj-in table room3 office) 0.7) (= (p-obj-in table room3 corridor) 0.1)
    (= (p-obj-in cerealbox new-room1 kitchen) 0.6) (= (p-obj-in cerealbox new-room1 office) 0.1) (= (p-obj-in cerealbox new-room1 corridor) 0.02)
    (= (p-obj-in table new-room1 kitchen) 0.9) (= (p-obj-in table new-room1 office) 0.7) (= (p-obj-in table new-room1 corridor) 0.1)
    (= (p-obj-in cerealbox new-room2 kitchen) 0.6) (= (p-obj-in cerealbox new-room2 office) 0.1) (= (p-obj-in cerealbox new-room2 corridor) 0.02)
    (= (p-obj-in table new-room2 kitchen) 0.9) (= (p-obj-in table new-room2 office) 0.7) (= (p-obj-in table new-room2 corridor) 0.1)
    ;; P(ObjectAt L^C): default knowledge, on an object of class S in a room of category C
    (= (p-obj-on cerealbox cerealbox kitchen) 0) (= (p-obj-on cerealbox cerealbox office) 0) (= (p-obj-on cerealbox cerealbox corridor) 0)
    (= (p-obj-on cerealbox table kitchen) 0.6) (= (p-obj-on cerealbox table office) 0.1) (= (p-obj-on cerealbox table corridor) 0.05)
    (= (p-obj-on table cerealbox kitchen) 0) (= (p-obj-on table cerealbox office) 0) (= (p-obj-on table cerealbox corridor) 0)
    (= (p-obj-on table table kitchen) 0) (= (p-obj-on table table office) 0) (= (p-obj-on table table corridor) 0)
    )
  (:goal (reported cerealbox))
  (:metric minimize (total-cost)))
