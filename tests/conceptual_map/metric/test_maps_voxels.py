"""The 3D voxel map: cell states from depth rays, the incremental frontier set, region reset."""

import numpy as np
import pytest

from conceptual_map.metric import CellState, SensorDataError, VoxelMap
from conceptual_map.metric.synthetic import BoxWorld, DepthFrame, rooms_world

TABLE = (1.0, 1.0, 1.6, 1.8)  # x0, y0, x1, y1; 0.75 m high
EYE = (2.2, 2.3, 1.37)
VIEWS = [(3.3, -0.5), (2.6, -0.3), (4.0, -0.6), (0.5, 0.0)]  # yaw, pitch


@pytest.fixture(scope="module")
def world() -> BoxWorld:
    world = rooms_world([(0.0, 0.0, 3.0, 4.0), (3.0, 0.0, 6.0, 4.0)], [(3.0, 2.0, 0.92)])
    world.add_box(*TABLE, 0.0, 0.75)
    return world


def frames(world: BoxWorld) -> list[DepthFrame]:
    return [world.depth(EYE, yaw, pitch) for yaw, pitch in VIEWS]


def test_frontier_set_stays_equal_to_its_definition(world: BoxWorld) -> None:
    voxels = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(7.0, 5.0, 2.0))
    for frame in frames(world):
        voxels.integrate_depth(frame)
        assert np.array_equal(voxels.frontier, voxels.compute_frontier())
    assert voxels.frontier.sum() > 100
    voxels.reset_box((0.8, 0.8, 0.0), (1.8, 2.0, 1.0))
    assert np.array_equal(voxels.frontier, voxels.compute_frontier())
    voxels.integrate_depth(world.depth(EYE, 3.3, -0.5))
    assert np.array_equal(voxels.frontier, voxels.compute_frontier())


def test_hit_voxels_are_occupied_and_ray_interiors_free(world: BoxWorld) -> None:
    voxels = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(7.0, 5.0, 2.0))
    frame = world.depth(EYE, 3.3, -0.5)
    voxels.integrate_depth(frame)
    states = voxels.states()
    hit = np.isfinite(frame.ranges)
    ends = frame.origin + frame.directions[hit] * frame.ranges[hit, None]
    cells = voxels.to_cell(ends)
    ok = voxels.inside(cells)
    assert np.mean(states[tuple(cells[ok].T)] == CellState.OCCUPIED) > 0.99
    halfway = frame.origin + frame.directions[hit] * (0.5 * frame.ranges[hit, None])
    assert np.all(states[tuple(voxels.to_cell(halfway).T)] == CellState.FREE)


def test_inside_of_the_table_and_the_far_room_stay_unknown(world: BoxWorld) -> None:
    voxels = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(7.0, 5.0, 2.0))
    for frame in frames(world):
        voxels.integrate_depth(frame)
    inner = voxels.unknown_in_box((1.1, 1.1, 0.1), (1.5, 1.7, 0.65))
    assert len(inner) == 8 * 12 * 11  # every voxel centre strictly inside the table
    assert len(voxels.unknown_in_box((4.5, 0.5, 0.5), (5.5, 1.0, 1.0))) > 0
    free_in_room_b = voxels.states()[tuple(voxels.to_cell(np.array([[5.0, 3.5, 1.0]]))[0])]
    assert free_in_room_b == CellState.UNKNOWN


def test_reset_box_forgets_exactly_the_box(world: BoxWorld) -> None:
    voxels = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(7.0, 5.0, 2.0))
    for frame in frames(world):
        voxels.integrate_depth(frame)
    before = voxels.states()
    lo, hi = (0.8, 0.8, 0.0), (1.8, 2.0, 1.0)
    summary = voxels.reset_box(lo, hi)
    after = voxels.states()
    centres = voxels.to_world(np.argwhere(np.ones(voxels.shape, dtype=bool))).reshape(
        voxels.shape + (3,)
    )
    inside = np.all((centres >= lo) & (centres <= hi), axis=-1)
    assert np.all(after[inside] == CellState.UNKNOWN)
    assert np.array_equal(after[~inside], before[~inside])
    assert summary.changed.size == int((before[inside] != CellState.UNKNOWN).sum()) > 0
    assert len(voxels.unknown_in_box(lo, hi)) == int(inside.sum())


def test_frontiers_in_box_adds_unknown_border_cells_only_when_asked(world: BoxWorld) -> None:
    voxels = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(7.0, 5.0, 2.0))
    voxels.integrate_depth(world.depth(EYE, 3.3, -0.5))
    lo, hi = (4.0, 1.0, 0.2), (5.0, 2.0, 1.0)  # room B, unseen: no frontier inside
    assert len(voxels.frontiers_in_box(lo, hi, include_border_unknown=False)) == 0
    border = voxels.frontiers_in_box(lo, hi)
    assert len(border) == 20 * 20 * 16 - 18 * 18 * 14


def test_office_sized_map_is_small() -> None:
    voxels = VoxelMap(size=(12.0, 8.0, 2.0))
    assert voxels.shape == (240, 160, 40)
    assert voxels.logodds.nbytes + voxels.frontier.nbytes <= 2 * 240 * 160 * 40


def test_rays_leaving_a_fixed_box_are_cut_at_its_border() -> None:
    voxels = VoxelMap(origin=(0.0, 0.0, 0.0), size=(1.0, 1.0, 1.0))
    frame = DepthFrame(np.array([0.5, 0.5, 0.5]), np.array([[1.0, 0.0, 0.0]]), np.array([3.0]), 4.0)
    voxels.integrate_depth(frame)
    assert voxels.shape == (20, 20, 20)
    assert (voxels.states()[10:, 10, 10] == CellState.FREE).all()


def test_non_unit_directions_are_rejected() -> None:
    frame = DepthFrame(np.zeros(3), np.array([[2.0, 0.0, 0.0]]), np.array([1.0]), 4.0)
    with pytest.raises(SensorDataError, match="unit vectors"):
        VoxelMap().integrate_depth(frame)


def test_a_growing_map_keeps_its_frontier_set_consistent(world: BoxWorld) -> None:
    voxels = VoxelMap(origin=(1.5, 1.5, 0.0), size=(1.0, 1.0, 2.0), grow=True)
    for frame in frames(world):
        voxels.integrate_depth(frame)
    assert voxels.origin[0] < 0.0 and voxels.shape[0] > 20  # grew to hold the room
    assert voxels.frontier.shape == voxels.shape
    assert np.array_equal(voxels.frontier, voxels.compute_frontier())
