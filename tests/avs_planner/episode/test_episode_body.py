"""The robot adapter tells the mind its own body (from the robot model, not the world)."""

import math

import pytest

from avs_planner.harness.sim_robot import load_spec, open_world


@pytest.mark.parametrize("model", ["pioneer", "pr2"])
def test_body_matches_the_robot_model(model: str) -> None:
    robot = open_world(load_spec("office", model), 0)
    try:
        body = robot.body()
        assert body.name == model
        assert body.camera_height == pytest.approx(robot.camera_height, abs=1e-6)
        assert body.drive_time(1.0) == pytest.approx(1.0 / body.linear_speed)
        assert body.turn_time(2 * math.pi + 0.5) == pytest.approx(0.5 / body.angular_speed)
        before = robot.clock
        robot.set_torso(body.torso.high + 1.0)  # clipped, never an error
        assert robot.camera_height == pytest.approx(body.camera_height + body.torso.high,
                                                    abs=1e-3)
        frame = robot.depth((8, 6))
        assert frame.directions.shape == (48, 3) and robot.clock > before
    finally:
        robot.world.close()


def test_pr2_is_bigger_and_has_a_torso() -> None:
    bodies = {}
    for model in ("pioneer", "pr2"):
        robot = open_world(load_spec("office", model), 0)
        bodies[model] = robot.body()
        robot.world.close()
    assert bodies["pr2"].footprint_radius > bodies["pioneer"].footprint_radius
    assert bodies["pr2"].torso.high > 0 == bodies["pioneer"].torso.high


def test_depth_frames_build_the_minds_3d_map_over_its_2d_grid() -> None:
    from avs_planner.episode.mind import Mind
    from conceptual_map.metric import CellState

    robot = open_world(load_spec("office", "pioneer"), 0)
    try:
        mind = Mind()
        mind.integrate(robot.scan())
        robot.look(0.0, -0.4)
        voxels = mind.integrate_depth(robot.depth((16, 12)))
        states = voxels.states()
        assert (states == CellState.FREE).any() and (states == CellState.OCCUPIED).any()
        assert voxels.origin[2] == pytest.approx(mind.voxel_heights[0])
        for _ in range(3):  # the 2D grid grows as the robot drives; so does the 3D map
            robot.move_along([(robot.pose[0] + 1.5, robot.pose[1])])
            mind.integrate(robot.scan())
            mind.integrate_depth(robot.depth((16, 12)))
        grid_hi = mind.grid.origin[0] + mind.grid.shape[0] * mind.grid.resolution
        vox_hi = voxels.origin[0] + voxels.shape[0] * voxels.resolution
        assert vox_hi >= grid_hi - 1e-6
    finally:
        robot.world.close()
