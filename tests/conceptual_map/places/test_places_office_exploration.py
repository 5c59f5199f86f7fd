"""Scripted exploration of the simulator's `office` world: coverage, rooms, doors, no leftovers.

Only this test reads the world file (to check the maps); the maps see laser scans and poses.
"""

import numpy as np
import pytest
from matplotlib.path import Path as Polygon
from scipy import ndimage

from conceptual_map.metric import CellState, OccupancyGrid
from conceptual_map.places import PlaceMap, PlaceMapConfig
from conceptual_map.places.exploration import ExplorationStatus, Explorer

sim = pytest.importorskip("sim")

RES = 0.05


@pytest.fixture(scope="module")
def explored():
    with sim.load_world("office", seed=1) as world:
        grid = OccupancyGrid(resolution=RES)
        place_map = PlaceMap(PlaceMapConfig(robot_radius=0.3))
        result = Explorer(world.robot, grid, place_map).run()
        yield world.spec, grid, place_map, result


def reachable_truth(spec) -> np.ndarray:
    """Centres (N, 2) of floor cells where the robot could stand, reachable from its start."""
    w, h = spec.size
    xx, yy = np.meshgrid(np.arange(RES / 2, w, RES), np.arange(RES / 2, h, RES), indexing="ij")
    centres = np.column_stack([xx.ravel(), yy.ravel()])
    half = spec.wall_thickness / 2
    open_ = np.zeros(len(centres), dtype=bool)
    for room in spec.rooms:
        x0, y0, x1, y1 = room.rect
        open_ |= _in_box(centres, x0 + half, y0 + half, x1 - half, y1 - half)
    for door in spec.doors:
        (x, y), r = door.at, door.width / 2
        open_ |= _in_box(centres, x - r, y - half, x + r, y + half)  # doors in walls along x
        open_ |= _in_box(centres, x - half, y - r, x + half, y + r)  # doors in walls along y
    for item in spec.furniture:
        open_ &= ~Polygon(item.footprint()).contains_points(centres)
    clearance = ndimage.distance_transform_edt(open_.reshape(xx.shape)) * RES - RES / 2
    standable = clearance >= sim.PIONEER.footprint_radius
    labels, _ = ndimage.label(standable)
    start = (int(spec.robot.start[0] / RES), int(spec.robot.start[1] / RES))
    return centres[(labels == labels[start]).ravel()]


def _in_box(p: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return (p[:, 0] > x0) & (p[:, 0] < x1) & (p[:, 1] > y0) & (p[:, 1] < y1)


def test_exploration_ends_with_no_placeholder_left(explored) -> None:
    _, _, place_map, result = explored
    assert result.status is ExplorationStatus.COMPLETE
    assert place_map.placeholders == {}


def test_grid_covers_the_reachable_free_space(explored) -> None:
    spec, grid, _, _ = explored
    truth = reachable_truth(spec)
    assert len(truth) * RES**2 > 40.0  # most of the 96 m^2 floor, less wall margins and furniture
    cells = grid.to_cell(truth)
    assert grid.inside(cells).all()
    states = grid.state_grid()[cells[:, 0], cells[:, 1]]
    assert np.mean(states == CellState.FREE) >= 0.95


def test_four_rooms_are_found_and_their_places_lie_in_one_world_room_each(explored) -> None:
    spec, _, place_map, _ = explored
    assert len(place_map.rooms) == len(spec.rooms) == 4
    found = []
    for room in place_map.rooms.values():
        names = set()
        for pid in room.places:
            x, y = place_map.places[pid].position
            names |= {r.name for r in spec.rooms if r.contains(x, y, margin=0.15)}
        assert len(names) == 1, (room.id, names)
        found.append(names.pop())
    assert sorted(found) == sorted(r.name for r in spec.rooms)


def test_every_open_door_was_found_and_passed(explored) -> None:
    spec, _, place_map, _ = explored
    for door in spec.doors:
        near = [
            d
            for d in place_map.doors.values()
            if np.hypot(d.centre[0] - door.at[0], d.centre[1] - door.at[1]) < 0.3
        ]
        assert len(near) == 1 and near[0].confirmed, door
        assert abs(near[0].width - door.width) <= 0.1


@pytest.mark.slow
@pytest.mark.parametrize("seed", [2, 3, 4])
def test_other_sensor_noise_seeds_find_the_same_four_rooms(seed: int) -> None:
    with sim.load_world("office", seed=seed) as world:
        grid, place_map = OccupancyGrid(resolution=RES), PlaceMap(PlaceMapConfig(robot_radius=0.3))
        result = Explorer(world.robot, grid, place_map).run()
        spec = world.spec
    assert result.status is ExplorationStatus.COMPLETE and place_map.placeholders == {}
    found = set()
    for room in place_map.rooms.values():
        names = {
            r.name
            for pid in room.places
            for r in spec.rooms
            if r.contains(*place_map.places[pid].position, margin=0.15)
        }
        assert len(names) == 1
        found |= names
    assert len(place_map.rooms) == 4 and found == {r.name for r in spec.rooms}
