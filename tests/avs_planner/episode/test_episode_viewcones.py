"""CREATEVIEWCONES: covering cones in a room, cones around a support; probabilities add up."""

from __future__ import annotations

import math

import numpy as np

from avs_planner.cp.search import PlanStep
from avs_planner.dt import DTProblem, TravelCosts
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.viewcones import (
    CameraModel,
    candidate_cells,
    room_cones,
    standpoints,
    support_cones,
)
from avs_planner.strategies.switching.loop import assumed_categories

CAMERA = CameraModel(height=1.4, hfov=math.radians(60), detect_range=4.0)


def test_room_cones_cover_the_room_and_split_its_probability(corridor_mind) -> None:
    mind, _, _ = corridor_mind
    room = mind.place_map.room_of(mind.place_map.current_place)
    made = room_cones(mind, room, "cerealbox", 0.6, CAMERA, "k")
    assert 1 <= len(made.cones) <= 6 and 0.5 <= made.coverage <= 1.0
    total = sum(c.probability for c in made.cones)
    assert math.isclose(total, 0.6 * made.coverage, rel_tol=1e-9)
    stands = standpoints(mind, room)
    free = mind.grid.traversable(mind.config.robot_radius)
    for cone in made.cones:
        # stands on a place, or on the room's free floor where the body fits
        assert min(math.dist(cone.pose[:2], p) for p in stands) < 1e-9
        assert free[mind.grid.cell_of(cone.pose[:2])]
        assert cone.head is not None and cone.head[1] < 0  # looks down at surfaces
    DTProblem(made.cones, TravelCosts.from_poses((6.0, 3.2, 0.0), made.cones))  # valid input


def _long_room() -> tuple[Mind, str]:
    """A 2.4 x 9 m room (walls 0.1 m thick) the robot has seen from one end only."""
    from conceptual_map.metric.synthetic import BoxWorld

    world = BoxWorld()
    for box in ((-0.1, -0.1, 9.1, 0.0), (-0.1, 2.4, 9.1, 2.5), (-0.1, -0.1, 0.0, 2.5),
                (9.0, -0.1, 9.1, 2.5)):
        world.add_box(*box)
    mind = Mind()
    for k, yaw in enumerate((0.0, math.pi)):
        pose = (1.0, 1.2, yaw)
        mind.sense(world.laser(pose, beams=1440, max_range=12.0), [pose], float(k))
    return mind, mind.place_map.room_of(mind.place_map.current_place)


def test_a_room_search_covers_the_room_beyond_camera_range_of_its_places() -> None:
    """The far end of a room is part of it (a miss there is evidence about the room) and a
    view stands where the camera reaches it, not only at the places the robot stood on."""
    mind, room = _long_room()
    points, rooms = candidate_cells(mind)
    mine = points[rooms == room]
    places = [p.position for p in mind.place_map.places.values()]
    far = mine[np.min([np.hypot(*(mine - p).T) for p in places], axis=0) > CAMERA.detect_range]
    assert len(far) > 0 and far[:, 0].max() > 8.5  # the far wall's cells are the room's
    made = room_cones(mind, room, "cup", 0.5, CAMERA, "k")
    reach = 0.9 * CAMERA.detect_range
    assert any(math.dist(c.pose[:2], (8.9, 1.2)) < reach for c in made.cones)
    free = mind.grid.traversable(mind.config.robot_radius)
    assert all(free[mind.grid.cell_of(c.pose[:2])] for c in made.cones)


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
