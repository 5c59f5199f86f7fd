"""The 2D grid from synthetic scans of two rooms joined by a door, checked against geometry."""

import numpy as np
import pytest

from conceptual_map.metric import CellState, OccupancyGrid, SensorDataError
from conceptual_map.metric.synthetic import BoxWorld, LaserScan, rooms_world

ROOMS = [(0.0, 0.0, 3.0, 4.0), (3.0, 0.0, 6.0, 4.0)]
DOOR = (3.0, 2.0, 0.92)  # jambs off cell borders: no ties in which cell a hit is in
POSES_A = [(1.0, 1.0, 0.0), (2.0, 3.0, np.pi), (1.5, 2.0, 0.5)]
MAX_RANGE = 5.6


def scanned(world: BoxWorld, poses: list) -> OccupancyGrid:
    grid = OccupancyGrid(origin=(-1.0, -1.0), size=(8.0, 6.0))
    for pose in poses:
        grid.integrate_scan(world.laser(pose, beams=1440, max_range=MAX_RANGE))
    return grid


def visibility(world: BoxWorld, grid: OccupancyGrid, poses: list) -> np.ndarray:
    """For each cell and each of 16 sample points in it: seen from at least one pose?"""
    ii, jj = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    offsets = np.linspace(0.02, 0.98, 4)
    ou, ov = np.meshgrid(offsets, offsets, indexing="ij")
    pts = (
        np.stack([ii[..., None] + ou.ravel(), jj[..., None] + ov.ravel()], axis=-1)
        * grid.resolution
        + grid.origin
    )
    flat = pts.reshape(-1, 2)
    seen = np.zeros(flat.shape[0], dtype=bool)
    # outside the outer walls nothing is visible: cast only from points inside the building
    building = np.all((flat > -0.06) & (flat < [6.06, 4.06]), axis=1)
    for x, y, _ in poses:
        vec = flat[building] - [x, y]
        dist = np.linalg.norm(vec, axis=1)
        dirs = np.column_stack([vec / dist[:, None], np.zeros(len(vec))])
        hit = world.cast(np.array([x, y, 0.3]), dirs, MAX_RANGE)
        seen[building] |= (dist < MAX_RANGE - 0.01) & (hit > dist)
    return seen.reshape(grid.shape + (16,))


def in_walls(world: BoxWorld, grid: OccupancyGrid) -> np.ndarray:
    """Cells that overlap a wall box."""
    lo = grid.origin
    out = np.zeros(grid.shape, dtype=bool)
    for x0, y0, _, x1, y1, _ in world.boxes:
        i0, j0 = np.floor((np.array([x0, y0]) - lo) / grid.resolution).astype(int)
        i1, j1 = np.ceil((np.array([x1, y1]) - lo) / grid.resolution).astype(int)
        out[max(i0, 0) : i1, max(j0, 0) : j1] = True
    return out


@pytest.fixture(scope="module")
def world() -> BoxWorld:
    return rooms_world(ROOMS, [DOOR])


@pytest.fixture(scope="module")
def grid_a(world: BoxWorld) -> OccupancyGrid:
    return scanned(world, POSES_A)


@pytest.fixture(scope="module")
def seen_a(world: BoxWorld, grid_a: OccupancyGrid) -> np.ndarray:
    return visibility(world, grid_a, POSES_A)


def test_fully_visible_cells_are_free(
    world: BoxWorld, grid_a: OccupancyGrid, seen_a: np.ndarray
) -> None:
    seen = seen_a
    must_be_free = seen.all(axis=2) & ~in_walls(world, grid_a)
    assert must_be_free.sum() > 1000
    assert np.all(grid_a.state_grid()[must_be_free] == CellState.FREE)


def test_unseen_cells_stay_unknown(
    world: BoxWorld, grid_a: OccupancyGrid, seen_a: np.ndarray
) -> None:
    seen = seen_a
    never_seen = ~seen.any(axis=2) & ~in_walls(world, grid_a)
    assert never_seen.sum() > 1000  # most of room B and everything outside
    assert np.all(grid_a.state_grid()[never_seen] == CellState.UNKNOWN)


def test_occupied_cells_are_wall_cells_and_seen_walls_are_occupied(
    world: BoxWorld, grid_a: OccupancyGrid
) -> None:
    states = grid_a.state_grid()
    assert np.all(in_walls(world, grid_a)[states == CellState.OCCUPIED])
    for pose in POSES_A:
        scan = world.laser(pose, beams=1440, max_range=MAX_RANGE)
        hits = np.isfinite(scan.ranges)
        ang = pose[2] + scan.angles[hits]
        ends = np.column_stack([np.cos(ang), np.sin(ang)]) * scan.ranges[hits, None] + pose[:2]
        cells = grid_a.to_cell(ends)
        occupied = states[cells[:, 0], cells[:, 1]] == CellState.OCCUPIED
        assert occupied.mean() > 0.99, pose  # a few grazing hits at door jambs may be cleared


def test_frontier_is_exactly_unknown_next_to_free(grid_a: OccupancyGrid) -> None:
    states = grid_a.state_grid()
    want = np.zeros(states.shape, dtype=bool)
    rows, cols = states.shape
    for i, j in zip(*np.nonzero(states == CellState.UNKNOWN), strict=True):
        for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            if 0 <= i + di < rows and 0 <= j + dj < cols and states[i + di, j + dj] == 1:
                want[i, j] = True
    assert np.array_equal(grid_a.frontier_mask(), want)


def test_frontier_of_a_fully_scanned_room_lies_behind_its_door(grid_a: OccupancyGrid) -> None:
    points = grid_a.to_world(np.argwhere(grid_a.frontier_mask()))
    assert len(points) > 0
    assert points[:, 0].min() > 3.0  # only in room B, seen through the door


def test_grid_grows_to_hold_scans_beyond_its_border(world: BoxWorld) -> None:
    grid = OccupancyGrid(origin=(0.5, 0.5), size=(1.0, 1.0))
    grid.integrate_scan(world.laser((1.0, 1.0, 0.0)))
    top = grid.origin + np.asarray(grid.shape) * grid.resolution
    assert np.all(grid.origin <= 0.06) and top[0] >= 5.94 and top[1] >= 3.94  # inner faces fit
    assert grid.state_grid()[grid.cell_of((1.0, 1.0))] == CellState.FREE
    assert grid.state_grid()[grid.cell_of((0.06, 1.0))] == CellState.OCCUPIED


def test_mismatched_scan_arrays_are_rejected_with_the_field_named() -> None:
    scan = LaserScan((0.0, 0.0, 0.0), np.zeros(3), np.ones(4), 5.0)
    with pytest.raises(SensorDataError, match="angles has 3 entries but ranges has 4"):
        OccupancyGrid().integrate_scan(scan)
