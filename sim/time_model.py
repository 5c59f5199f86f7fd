"""The time model: how many simulated seconds each motion and sensing action takes.

Driving at `linear_speed`, turning in place at `angular_speed`, the torso at `torso_speed`, the
head's pan and tilt moving together (the slower axis decides), and a fixed cost per laser scan or
depth frame (`scan_time`) and per semantic detection or place classification (`sensing_time`).
Planners predict with the same numbers: driving + torso + pan/tilt + sensing, as in §3 of the
FLAP paper by Gedicke et al.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class TimeModel:
    """Speeds (m/s, rad/s) and fixed sensing costs (s) of one robot."""

    linear_speed: float
    angular_speed: float
    torso_speed: float
    pan_speed: float
    tilt_speed: float
    scan_time: float
    sensing_time: float

    def drive(self, distance: float) -> float:
        """Seconds to drive `distance` metres in a straight line."""
        return abs(distance) / self.linear_speed

    def turn(self, angle: float) -> float:
        """Seconds to turn in place by `angle` (the short way round)."""
        return abs(wrap_angle(angle)) / self.angular_speed

    def torso(self, delta: float) -> float:
        """Seconds to move the torso by `delta` metres (0 when it does not move)."""
        return 0.0 if delta == 0.0 else abs(delta) / self.torso_speed

    def head(self, delta_pan: float, delta_tilt: float) -> float:
        """Seconds to move the head; pan and tilt move at once, so the slower axis decides."""
        return max(abs(delta_pan) / self.pan_speed, abs(delta_tilt) / self.tilt_speed)

    def path(self, start: Sequence[float], points: Sequence[Sequence[float]],
             holonomic: bool = False) -> float:
        """Seconds to follow waypoints from `start` (x, y, yaw).

        A differential robot turns towards each segment, then drives it; a holonomic one
        drives every segment without turning.
        """
        x, y, yaw = start
        total = 0.0
        for px, py in points:
            dist = math.hypot(px - x, py - y)
            if dist > 1e-9 and not holonomic:
                heading = math.atan2(py - y, px - x)
                total += self.turn(heading - yaw)
                yaw = heading
            total += self.drive(dist)
            x, y = px, py
        return total


def wrap_angle(angle: float) -> float:
    """The same angle in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
