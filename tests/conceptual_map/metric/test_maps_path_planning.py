"""A* on the inflated grid: avoids walls by the robot radius, fails cleanly when it cannot."""

import math

import numpy as np
import pytest

from conceptual_map.metric import (
    OccupancyGrid,
    PathQueryError,
    PathStatus,
    distance_field,
    plan_path,
)
from conceptual_map.metric.synthetic import BoxWorld, rooms_world

ROOMS = [(0.0, 0.0, 3.0, 4.0), (3.0, 0.0, 6.0, 4.0)]
DOOR = (3.0, 2.0, 0.92)
POSES = [(1.0, 1.0, 0.0), (2.0, 3.0, 3.1), (4.5, 2.0, 0.0), (5.0, 3.3, 2.0), (5.0, 0.7, 1.0)]


def wall_distance(world: BoxWorld, points: np.ndarray) -> np.ndarray:
    """Exact distance from each 2D point to the nearest wall box."""
    b = np.asarray(world.boxes)
    dx = np.maximum(np.maximum(b[None, :, 0] - points[:, :1], 0), points[:, :1] - b[None, :, 3])
    dy = np.maximum(np.maximum(b[None, :, 1] - points[:, 1:], 0), points[:, 1:] - b[None, :, 4])
    return np.hypot(dx, dy).min(axis=1)


def densify(waypoints: tuple) -> np.ndarray:
    pts = np.asarray(waypoints)
    out = [
        a + (b - a) * t
        for a, b in zip(pts[:-1], pts[1:], strict=True)
        for t in np.linspace(0, 1, 100)
    ]
    return np.asarray(out)


@pytest.fixture(scope="module")
def world() -> BoxWorld:
    return rooms_world(ROOMS, [DOOR])


@pytest.fixture(scope="module")
def grid(world: BoxWorld) -> OccupancyGrid:
    grid = OccupancyGrid(origin=(-1.0, -1.0), size=(8.0, 6.0))
    for pose in POSES:
        grid.integrate_scan(world.laser(pose, beams=1440))
    return grid


@pytest.mark.parametrize("radius", [0.2, 0.3, 0.4])
def test_path_through_the_door_keeps_the_robot_radius_from_walls(
    world: BoxWorld, grid: OccupancyGrid, radius: float
) -> None:
    start, goal = (0.6, 0.6), (5.4, 3.4)
    result = plan_path(grid, start, goal, robot_radius=radius)
    assert result.status is PathStatus.FOUND
    assert result.waypoints[0] == start and result.waypoints[-1] == goal
    points = densify(result.waypoints)
    assert wall_distance(world, points).min() >= radius - grid.resolution
    crossing = points[np.argmin(np.abs(points[:, 0] - 3.0))]
    assert abs(crossing[1] - 2.0) < 0.46 - radius + grid.resolution  # through the gap
    assert (
        math.dist(start, goal)
        <= result.length
        <= distance_field(grid, start, radius)[grid.cell_of(goal)]
    )


def test_robot_wider_than_the_door_gets_no_path(grid: OccupancyGrid) -> None:
    result = plan_path(grid, (1.5, 2.0), (4.5, 2.0), robot_radius=0.5)
    assert result.status is PathStatus.NO_PATH
    assert result.waypoints == () and result.length == math.inf


def test_path_within_a_room_is_a_straight_line(grid: OccupancyGrid) -> None:
    result = plan_path(grid, (0.7, 0.7), (2.2, 3.2), robot_radius=0.25)
    assert len(result.waypoints) == 2
    assert result.length == pytest.approx(math.dist((0.7, 0.7), (2.2, 3.2)))


def test_goal_in_a_wall_is_an_error_naming_the_goal(grid: OccupancyGrid) -> None:
    with pytest.raises(PathQueryError, match=r"goal \(3.00, 1.00\) is blocked"):
        plan_path(grid, (1.0, 1.0), (3.0, 1.0))


def test_goal_too_close_to_a_wall_is_an_error(grid: OccupancyGrid) -> None:
    with pytest.raises(PathQueryError, match="closer than the robot radius"):
        plan_path(grid, (1.0, 1.0), (0.2, 1.0), robot_radius=0.3)


def test_start_outside_the_map_is_an_error(grid: OccupancyGrid) -> None:
    with pytest.raises(PathQueryError, match=r"start \(40.00, 1.00\) is outside the map"):
        plan_path(grid, (40.0, 1.0), (1.0, 1.0))


def test_start_in_the_inflation_zone_can_escape(grid: OccupancyGrid) -> None:
    result = plan_path(grid, (0.2, 2.0), (1.5, 2.0), robot_radius=0.3)
    assert result.status is PathStatus.FOUND


def test_distance_field_is_inf_where_unreachable(grid: OccupancyGrid) -> None:
    field = distance_field(grid, (1.0, 1.0), robot_radius=0.25)
    assert field[grid.cell_of((1.0, 1.0))] == 0.0
    assert np.isinf(field[grid.cell_of((-0.5, -0.5))])  # outside the building
    assert field[grid.cell_of((5.0, 3.0))] > math.dist((1.0, 1.0), (5.0, 3.0))


def test_unknown_cells_under_the_robot_do_not_wall_it_in(world: BoxWorld) -> None:
    """A laser never sees the floor under its own base: those cells stay unknown, but the
    robot stands there, so paths and distances start from it."""
    blind = OccupancyGrid(origin=(-1.0, -1.0), size=(8.0, 6.0))
    blind.integrate_scan(world.laser((1.5, 2.0, 0.0), beams=1440))
    blind.integrate_scan(world.laser((1.5, 2.0, math.pi), beams=1440))
    c = blind.cell_of((1.5, 2.0))
    ii, jj = np.mgrid[c[0] - 3:c[0] + 4, c[1] - 3:c[1] + 4]  # what the base hides
    blind.reset_cells(np.ravel_multi_index((ii.ravel(), jj.ravel()), blind.shape))
    start = (1.5, 2.0)
    field = distance_field(blind, start, robot_radius=0.25)
    assert np.isfinite(field[blind.cell_of((2.3, 2.0))])
    assert plan_path(blind, start, (2.3, 2.0), robot_radius=0.25).status is PathStatus.FOUND
    # an obstacle under the base is still an obstacle: only unknown cells are assumed free
    assert np.isinf(field[blind.cell_of((-0.5, -0.5))])


def test_a_squeeze_keeps_the_comfort_margin_except_where_it_must_squeeze(
    world: BoxWorld, grid: OccupancyGrid
) -> None:
    """Slim margin 0.3 m, comfort 0.42 m, through the 0.92 m door from a corner of one room
    to the far corner of the other: string pulling on the slim mask alone cuts a diagonal
    that passes the jamb at the slim margin; with `comfort` the path leaves the comfortable
    space only for the cells A* had to use in the doorway, so it passes further from the
    walls (and no nearer than the slim margin anywhere)."""
    start, goal = (0.6, 3.4), (5.4, 0.6)
    slim = plan_path(grid, start, goal, robot_radius=0.3)
    kept = plan_path(grid, start, goal, robot_radius=0.3, comfort=0.42)
    assert slim.status is kept.status is PathStatus.FOUND
    near_slim = wall_distance(world, densify(slim.waypoints)).min()
    near_kept = wall_distance(world, densify(kept.waypoints)).min()
    assert near_kept >= 0.3 - grid.resolution
    assert near_kept > near_slim + 0.02
    assert kept.waypoints[0] == start and kept.waypoints[-1] == goal
    # no comfort beyond the path's own margin changes nothing
    same = plan_path(grid, start, goal, robot_radius=0.3, comfort=0.3)
    assert same.waypoints == slim.waypoints
