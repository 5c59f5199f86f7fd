"""CREATEVIEWCONES: covering cones in a room, cones around a support; probabilities add up."""

from __future__ import annotations

import math

from avs_planner.cp.search import PlanStep
from avs_planner.dt import DTProblem, TravelCosts
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.viewcones import CameraModel, room_cones, support_cones
from avs_planner.strategies.switching.loop import assumed_categories

CAMERA = CameraModel(height=1.4, hfov=math.radians(60), detect_range=4.0)


def test_room_cones_cover_the_room_and_split_its_probability(corridor_mind) -> None:
    mind, _, _ = corridor_mind
    room = mind.place_map.room_of(mind.place_map.current_place)
    made = room_cones(mind, room, "cerealbox", 0.6, CAMERA, "k")
    assert 1 <= len(made.cones) <= 6 and 0.5 <= made.coverage <= 1.0
    total = sum(c.probability for c in made.cones)
    assert math.isclose(total, 0.6 * made.coverage, rel_tol=1e-9)
    places = [p.position for p in mind.place_map.places.values()]
    for cone in made.cones:
        assert min(math.dist(cone.pose[:2], p) for p in places) < 1e-9  # stands on a place
        assert cone.head is not None and cone.head[1] < 0  # looks down at surfaces
    DTProblem(made.cones, TravelCosts.from_poses((6.0, 3.2, 0.0), made.cones))  # valid input


def test_support_cones_face_the_support_from_free_space(corridor_mind) -> None:
    mind, _, _ = corridor_mind
    x, y = mind.place_map.places[mind.place_map.current_place].position
    support = KnownObject("object9", "table", (x + 0.5, y, 0.375), "room1")
    made = support_cones(mind, support, 0.4, CAMERA, "s")
    assert 1 <= len(made.cones) <= 4
    assert math.isclose(sum(c.probability for c in made.cones), 0.4)
    free = mind.grid.traversable(mind.config.robot_radius)
    for cone in made.cones:
        cx, cy, yaw = cone.pose
        assert free[mind.grid.cell_of((cx, cy))]
        bearing = math.atan2(support.position[1] - cy, support.position[0] - cx)
        assert abs(math.remainder(bearing - yaw, math.tau)) < 1e-6
        assert 0.8 <= math.dist((cx, cy), support.position[:2]) <= 1.6


def test_assumed_categories_come_from_the_plan() -> None:
    plan = [PlanStep("assume-leads-to-room", ("ph1", "kitchen", "new-room1"), 0, 0.5, True),
            PlanStep("assume-category", ("room2", "office"), 0, 0.7, True),
            PlanStep("move", ("p1", "ph1"), 3, 1.0)]
    assert assumed_categories(plan) == {"new-room1": "kitchen", "room2": "office"}
