"""The robot adapter tells the mind its own body (from the robot model, not the world)."""

import math

import pytest

from avs_planner.episode.robot import load_spec, open_world


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
