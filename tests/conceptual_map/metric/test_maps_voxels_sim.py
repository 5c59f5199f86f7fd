"""The voxel map fed with the simulator's depth frames in the office corridor."""

import numpy as np
import pytest

from conceptual_map.metric import CellState, VoxelMap

sim = pytest.importorskip("sim")


@pytest.fixture(scope="module")
def corridor_voxels() -> tuple[VoxelMap, list]:
    voxels, frames = VoxelMap(origin=(0.0, 0.0, 0.0), size=(12.0, 8.0, 2.0)), []
    with sim.load_world("office", seed=3) as world:
        robot = world.robot
        for pan in np.linspace(-1.4, 1.4, 5):
            robot.set_head(float(pan), -0.3)
            frames.append(robot.depth((64, 48)))
            voxels.integrate_depth(frames[-1])
            assert np.array_equal(voxels.frontier, voxels.compute_frontier())
    return voxels, frames


def test_surfaces_seen_in_depth_are_occupied(corridor_voxels) -> None:
    voxels, frames = corridor_voxels
    states = voxels.states()
    points = np.vstack([f.points() for f in frames])
    cells = voxels.to_cell(points)
    cells = cells[voxels.inside(cells)]
    assert len(cells) > 5000
    assert np.mean(states[tuple(cells.T)] == CellState.OCCUPIED) > 0.9


def test_corridor_air_is_free_and_the_rooms_behind_walls_unknown(corridor_voxels) -> None:
    voxels, _ = corridor_voxels
    corridor_air = voxels.states()[tuple(voxels.to_cell(np.array([[8.0, 3.25, 1.0]]))[0])]
    assert corridor_air == CellState.FREE
    behind_wall = voxels.unknown_in_box((8.5, 0.8, 0.5), (10.5, 1.5, 1.0))  # office2, no door
    assert len(behind_wall) == 40 * 14 * 10
    assert voxels.frontier.sum() > 0
