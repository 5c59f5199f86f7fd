"""The time model on its own: the numbers planners use to predict."""

from __future__ import annotations

import math

import pytest

from sim.time_model import TimeModel, wrap_angle

MODEL = TimeModel(linear_speed=0.5, angular_speed=1.0, torso_speed=0.02, pan_speed=2.0,
                  tilt_speed=1.0, scan_time=0.1, sensing_time=0.5)


def test_drive_turn_torso_head() -> None:
    assert MODEL.drive(2.0) == pytest.approx(4.0)
    assert MODEL.turn(3 * math.pi / 2) == pytest.approx(math.pi / 2)  # the short way
    assert MODEL.torso(-0.1) == pytest.approx(5.0)
    assert MODEL.head(1.0, 0.2) == pytest.approx(0.5)  # pan is the slower axis here
    assert MODEL.head(0.2, 1.0) == pytest.approx(1.0)


def test_path_turns_before_each_segment_unless_holonomic() -> None:
    square = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    turns = 2 * (math.pi / 2)
    assert MODEL.path((0.0, 0.0, 0.0), square) == pytest.approx(3 / 0.5 + turns)
    assert MODEL.path((0.0, 0.0, math.pi), square, holonomic=True) == pytest.approx(3 / 0.5)
    assert MODEL.path((0.0, 0.0, math.pi), square) == pytest.approx(3 / 0.5 + turns + math.pi)


def test_wrap_angle() -> None:
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-math.pi / 4) == pytest.approx(-math.pi / 4)
