"""Map helpers the FLAP planner uses: several distance fields at once, cells of a box."""

import numpy as np

from conceptual_map.metric import (
    CellState,
    OccupancyGrid,
    Rays,
    VoxelMap,
    distance_field,
    distance_fields,
    distances_at,
)
from conceptual_map.metric.synthetic import rooms_world


def test_distance_fields_match_one_at_a_time() -> None:
    world = rooms_world([(0.0, 0.0, 4.0, 3.0)], [])
    world.add_box(1.5, 1.0, 2.5, 2.0, 0.0, 0.75)
    grid = OccupancyGrid(origin=(-0.3, -0.3), size=(4.6, 3.6), resolution=0.1)
    for pose in [(0.6, 0.6, 0.0), (3.2, 2.3, 0.0)]:
        grid.integrate_scan(world.laser(pose, beams=360, max_range=6.0))
    starts = [(0.6, 0.6), (3.2, 2.3), (1.0, 2.4)]
    fields = distance_fields(grid, starts, robot_radius=0.3)
    assert np.isfinite(fields[0][grid.cell_of((3.2, 2.3))])
    for k, start in enumerate(starts):
        np.testing.assert_array_equal(fields[k], distance_field(grid, start, 0.3))
    # read at some cells only (every cell, walls and unknown ones included): the same values
    cells = np.argwhere(np.ones(grid.shape, dtype=bool))
    at = distances_at(grid, starts, cells, robot_radius=0.3)
    np.testing.assert_allclose(at, fields[:, cells[:, 0], cells[:, 1]], rtol=1e-12)
    assert np.isinf(at).any() and np.isfinite(at).any()
    # a start inside an obstacle's inflation zone escapes as distance_fields does
    inside = [(1.45, 1.5)]
    np.testing.assert_allclose(distances_at(grid, inside, cells, 0.3),
                               distance_fields(grid, inside, 0.3)[:, cells[:, 0], cells[:, 1]])


def test_cells_in_box_and_states_at() -> None:
    voxels = VoxelMap(origin=(0.0, 0.0, 0.0), size=(1.0, 1.0, 1.0), resolution=0.25)
    cells = voxels.cells_in_box((0.0, 0.0, 0.0), (0.5, 0.25, 0.25))
    assert sorted(map(tuple, cells.tolist())) == [(0, 0, 0), (1, 0, 0)]
    ray = Rays(np.array([[0.01, 0.1, 0.1]]), np.array([[0.99, 0.1, 0.1]]), np.array([True]))
    for _ in range(3):
        voxels.integrate_rays(ray)
    flat = np.ravel_multi_index(tuple(cells.T), voxels.shape)
    assert voxels.states_at(flat).tolist() == [CellState.FREE, CellState.FREE]
    assert voxels.states_at(np.array([0]))[0] == CellState.FREE
    end = np.ravel_multi_index((3, 0, 0), voxels.shape)
    assert voxels.states_at(np.array([end]))[0] == CellState.OCCUPIED
