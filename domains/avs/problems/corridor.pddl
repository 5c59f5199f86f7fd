;; Goebelbecker et al., "A Planning Approach to Active Visual Search in Large Environments",
;; section 4, first plan: the robot is in the middle of the corridor (room1) and
;; nothing is explored yet. Placeholder place1 lies behind a door hypothesis (likely a new
;; room, probably a kitchen); placeholder place3 is the open end of the corridor.
;; Target: a cerealbox. Expected best plan for c + R(1 - p), R = 500 (see domains/README.md):
;;   assume-leads-to-room place1 kitchen new-room1
;;   assume-obj-exists-in table new-room1 kitchen new-object1
;;   assume-obj-exists-on cerealbox new-object1 table kitchen new-room1 new-object2
;;   move place0 place1, createviewcones-in table new-room1,
;;   searchforobject-in table new-room1 new-object1 place1, createviewcones-on cerealbox new-object1,
;;   searchforobject-on cerealbox new-object1 new-object2 new-room1 place1,
;;   reportposition new-object2 cerealbox
(define (problem corridor)
  (:domain avs)
  (:objects
    place0 place2 - place
    place1 place3 - placeholder
    room1 new-room1 new-room2 - room
    new-object1 new-object2 new-object3 - visualobject
    cerealbox table - label
    kitchen office corridor - category)
  (:init
    (at place0) (visited place0) (visited place2)
    (connected place0 place1) (connected place1 place0)
    (connected place0 place2) (connected place2 place0)
    (connected place2 place3) (connected place3 place2)
    (in-room place0 room1) (in-room place2 room1) (in-room place1 room1) (in-room place3 room1)
    (has-category room1 corridor) (defined-category room1)
    (virtual new-room1) (virtual new-room2)
    (virtual new-object1) (virtual new-object2) (virtual new-object3)
    (= (total-cost) 0)
    ;; path lengths in metres (0 where there is no path)
    (= (move-cost place0 place0) 0) (= (move-cost place0 place1) 3)
    (= (move-cost place0 place2) 4) (= (move-cost place0 place3) 0)
    (= (move-cost place1 place0) 3) (= (move-cost place1 place1) 0)
    (= (move-cost place1 place2) 0) (= (move-cost place1 place3) 0)
    (= (move-cost place2 place0) 4) (= (move-cost place2 place1) 0)
    (= (move-cost place2 place2) 0) (= (move-cost place2 place3) 3)
    (= (move-cost place3 place0) 0) (= (move-cost place3 place1) 0)
    (= (move-cost place3 place2) 3) (= (move-cost place3 place3) 0)
    (= (search-cost table in) 40) (= (search-cost table on) 10)
    (= (search-cost cerealbox in) 120) (= (search-cost cerealbox on) 10)
    (= (p-detect table in) 0.8) (= (p-detect table on) 0.8)
    (= (p-detect cerealbox in) 0.5) (= (p-detect cerealbox on) 0.8)
    (= (p-find-on table new-object1) 0.8) (= (p-find-on table new-object2) 0.8) (= (p-find-on table new-object3) 0.8)
    (= (p-find-on cerealbox new-object1) 0.8) (= (p-find-on cerealbox new-object2) 0.8) (= (p-find-on cerealbox new-object3) 0.8)
    ;; P_category(room): the corridor is known
    (= (p-room-category room1 corridor) 1) (= (p-room-category room1 kitchen) 0)
    (= (p-room-category room1 office) 0)
    (= (p-room-category new-room1 corridor) 0) (= (p-room-category new-room1 kitchen) 0)
    (= (p-room-category new-room1 office) 0)
    (= (p-room-category new-room2 corridor) 0) (= (p-room-category new-room2 kitchen) 0)
    (= (p-room-category new-room2 office) 0)
    ;; P_category(placeholder): the door at place1 probably leads into a kitchen
    (= (p-placeholder-category place1 kitchen) 0.6) (= (p-placeholder-category place1 office) 3/10)
    (= (p-placeholder-category place1 corridor) 0.05)
    (= (p-placeholder-category place3 kitchen) 0.2) (= (p-placeholder-category place3 office) 0.5)
    (= (p-placeholder-category place3 corridor) 0.1)
    ;; P(ObjectAt L) for rooms; unexplored (virtual) rooms get the category defaults
    (= (p-obj-in table room1 kitchen) 0.9) (= (p-obj-in table room1 office) 0.7)
    (= (p-obj-in table room1 corridor) 0.1)
    (= (p-obj-in cerealbox room1 kitchen) 0.6) (= (p-obj-in cerealbox room1 office) 0.1)
    (= (p-obj-in cerealbox room1 corridor) 0.02)
    (= (p-obj-in table new-room1 kitchen) 0.9) (= (p-obj-in table new-room1 office) 0.7)
    (= (p-obj-in table new-room1 corridor) 0.1)
    (= (p-obj-in cerealbox new-room1 kitchen) 0.6) (= (p-obj-in cerealbox new-room1 office) 0.1)
    (= (p-obj-in cerealbox new-room1 corridor) 0.02)
    (= (p-obj-in table new-room2 kitchen) 0.9) (= (p-obj-in table new-room2 office) 0.7)
    (= (p-obj-in table new-room2 corridor) 0.1)
    (= (p-obj-in cerealbox new-room2 kitchen) 0.6) (= (p-obj-in cerealbox new-room2 office) 0.1)
    (= (p-obj-in cerealbox new-room2 corridor) 0.02)
    ;; P(ObjectAt L^C): default knowledge, "on an object of class S in a room of category C"
    (= (p-obj-on cerealbox table kitchen) 0.6) (= (p-obj-on cerealbox table office) 0.1)
    (= (p-obj-on cerealbox table corridor) 0.05)
    (= (p-obj-on cerealbox cerealbox kitchen) 0) (= (p-obj-on cerealbox cerealbox office) 0)
    (= (p-obj-on cerealbox cerealbox corridor) 0)
    (= (p-obj-on table table kitchen) 0) (= (p-obj-on table table office) 0)
    (= (p-obj-on table table corridor) 0)
    (= (p-obj-on table cerealbox kitchen) 0) (= (p-obj-on table cerealbox office) 0)
    (= (p-obj-on table cerealbox corridor) 0))
  (:goal (reported cerealbox))
  (:metric minimize (total-cost)))
