"""Robot motion: collision-checked paths, the time model, joint limits, several worlds."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sim.errors import JointLimitError, MotionError, PathBlockedError
from sim.robot_models import PIONEER, PR2
from sim.scene import load_world

DATA = Path(__file__).parent / "data"


def test_move_along_refuses_a_path_through_a_wall_and_does_not_move() -> None:
    with load_world("office") as world:
        robot = world.robot
        before, clock = robot.pose, robot.clock
        with pytest.raises(PathBlockedError, match=r"segment 1 .* blocked .* by wall y=4"):
            robot.move_along([(5.0, 3.2), (5.0, 6.0)])
        assert robot.pose == before and robot.clock == clock and robot.odometry == 0.0


def test_move_along_through_a_door_and_charges_the_time_model() -> None:
    with load_world("office") as world:
        robot = world.robot
        result = robot.move_along([(7.0, 3.2), (7.0, 5.5)])
        expected = 1.0 / 0.5 + (math.pi / 2) / 1.0 + 2.3 / 0.5  # drive, turn left, drive
        assert result.duration == pytest.approx(expected)
        assert robot.clock == pytest.approx(expected)
        assert robot.pose == pytest.approx((7.0, 5.5, math.pi / 2))
        assert robot.room() == "office1"
        assert result.distance == pytest.approx(3.3)


def test_closed_door_blocks_until_opened() -> None:
    with load_world(DATA / "sensor_room.yaml") as world:
        path = [(1.0, 0.6), (5.5, 0.6)]
        with pytest.raises(PathBlockedError, match="closed door 0"):
            world.robot.move_along(path)
        world.set_door_open(0, True)
        world.robot.move_along(path)
        assert world.robot.room() == "store"


def test_furniture_blocks_the_footprint() -> None:
    with load_world(DATA / "sensor_room.yaml") as world:
        with pytest.raises(PathBlockedError, match="table1"):
            world.robot.move_along([(3.0, 2.0), (3.0, 0.5)])


def test_turn_to_takes_the_short_way() -> None:
    with load_world("office") as world:
        result = world.robot.turn_to(-3.0)
        assert result.duration == pytest.approx(3.0 / PIONEER.time.angular_speed)
        result = world.robot.turn_to(3.0)  # from -3.0 through pi: 2*pi - 6 rad
        assert result.duration == pytest.approx((2 * math.pi - 6.0) / PIONEER.time.angular_speed)


def test_pr2_is_holonomic_and_keeps_its_heading() -> None:
    with load_world("flap_two_rooms") as world:
        robot = world.robot
        result = robot.move_along([(2.5, 2.0)])
        assert result.duration == pytest.approx(1.0 / PR2.time.linear_speed)
        assert robot.pose[2] == pytest.approx(0.0)


def test_joint_limits_are_enforced_and_nothing_changes() -> None:
    with load_world("flap_two_rooms") as world:
        robot = world.robot
        assert robot.set_torso(0.31).duration == pytest.approx(0.31 / PR2.time.torso_speed)
        limits = r"torso 0.32 m is outside the limits \[0, 0.31\]"
        with pytest.raises(JointLimitError, match=limits):
            robot.set_torso(0.32)
        with pytest.raises(JointLimitError, match="tilt"):
            robot.set_head(0.0, math.radians(56.0))
        with pytest.raises(JointLimitError, match="pan"):
            robot.set_head(math.radians(176.0), 0.0)
        assert robot.torso == 0.31 and robot.head == (0.0, 0.0)
    with load_world("office") as world, pytest.raises(JointLimitError, match="torso"):
        world.robot.set_torso(0.1)


def test_head_pan_and_tilt_move_together() -> None:
    with load_world("flap_two_rooms") as world:
        result = world.robot.set_head(1.0, -0.5)
        assert result.duration == pytest.approx(max(1.0 / 2.0, 0.5 / 2.0))


def test_camera_height_follows_the_torso() -> None:
    with load_world("flap_two_rooms") as world:
        robot = world.robot
        assert robot.camera_view().origin[2] == pytest.approx(1.20)
        robot.set_torso(0.31)
        assert robot.camera_view().origin[2] == pytest.approx(1.51)
        robot.set_head(math.pi / 2, math.radians(-30.0))
        view = robot.camera_view()
        assert view.yaw == pytest.approx(math.pi / 2)
        assert view.pitch == pytest.approx(math.radians(-30.0))
    with load_world("office") as world:
        assert world.robot.camera_view().origin[2] == pytest.approx(1.40)
        assert world.robot.scan().height == pytest.approx(0.30)


def test_sensing_costs_time() -> None:
    with load_world("office") as world:
        robot = world.robot
        robot.scan()
        robot.detect()
        robot.depth()
        t = PIONEER.time
        assert robot.clock == pytest.approx(2 * t.scan_time + t.sensing_time)


def test_bad_waypoint_is_a_clear_error() -> None:
    with load_world("office") as world:
        with pytest.raises(MotionError, match="waypoint 1 must be finite"):
            world.robot.move_along([(6.5, 3.2), (float("nan"), 3.0)])


def test_several_worlds_live_side_by_side() -> None:
    first = load_world("office")
    second = load_world("office")
    try:
        assert first.client._client != second.client._client
        first.robot.move_along([(7.0, 3.2)])
        assert second.robot.pose == (6.0, 3.2, 0.0)
        first.close()
        scan = second.robot.scan()
        assert scan.ranges.size == PIONEER.laser.beams
    finally:
        first.close()
        second.close()


def test_blocked_by_explains_without_moving() -> None:
    with load_world("office") as world:
        robot = world.robot
        assert robot.blocked_by([(7.0, 3.2), (7.0, 5.5)]) is None
        reason = robot.blocked_by([(5.0, 3.2), (5.0, 6.0)])
        assert reason is not None and "wall y=4" in reason
        assert robot.pose == (6.0, 3.2, 0.0) and robot.clock == 0.0
