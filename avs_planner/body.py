"""The robot's own body as the mind knows it: footprint, sensor mounts, joint limits, speeds.

A real robot knows its URDF; these numbers are not ground truth about the world. The episode
wiring fills a `RobotBody` from the robot model through the robot adapter (`SimRobot.body`);
planners (view cones, FLAP view sampling, QSR view selection, path planning, time predictions)
take it as a parameter and never read the simulator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# m the mind keeps between its footprint circle and mapped obstacles, beyond the grid's own
# conservatism (`OccupancyGrid.clearance` is a lower bound on the distance to the surface that
# made a cell occupied: half a 5 cm cell's diagonal less than the distance to its centre);
# walls are ~1-2 cm noisy and the simulator refuses any contact deeper than 0.1 mm. Measured
# on the PR2 (0.34 m), scenarios a-f x 3 seeds: with 0.02 m, 18/18 right; with 0, the base
# touched walls it drove along (b, d: 2/3 each). With 0.04 m (0.38 m) the office's 0.9 m door
# closed in the grid (scenario a gave up). What the grid does not show the base's contact
# sense reports and the mind learns (`avs_planner/episode/blockages.py`). The Pioneer keeps
# the 0.04 m it always had (`SimRobot.body`).
PLANNING_CLEARANCE = 0.02


@dataclass(frozen=True)
class JointRange:
    """A closed range [low, high] of a joint, in metres or radians."""

    low: float
    high: float

    def clip(self, value: float) -> float:
        return min(max(value, self.low), self.high)

    def contains(self, value: float) -> bool:
        return self.low - 1e-9 <= value <= self.high + 1e-9


@dataclass(frozen=True)
class RobotBody:
    """Geometry, limits and time model of the robot the mind drives."""

    name: str
    footprint_radius: float  # m: the base's collision circle
    holonomic: bool
    camera_height: float  # m: camera above the floor with the torso at its lowest
    torso: JointRange  # m of lift above `camera_height` (0..0 without a torso)
    pan: JointRange  # rad, relative to the base heading
    tilt: JointRange  # rad, negative looks down
    hfov: float  # rad
    vfov: float  # rad
    depth_range: float  # m
    detect_range: float  # m: objects are recognised up to here
    laser_range: float  # m
    linear_speed: float  # m/s
    angular_speed: float  # rad/s
    torso_speed: float  # m/s
    pan_speed: float  # rad/s
    tilt_speed: float  # rad/s
    scan_time: float  # s per laser scan or depth frame
    sensing_time: float  # s per detection or place classification
    clearance: float = PLANNING_CLEARANCE  # m kept beyond the footprint when planning paths

    @property
    def planning_radius(self) -> float:
        """The disc the mind's path planning, reachability and standpoints keep clear."""
        return round(self.footprint_radius + self.clearance, 3)

    @property
    def passing_width(self) -> float:
        """The narrowest opening (door) the mind plans through with its full margin (where
        its grid shows less, it may still squeeze: `avs_planner.episode.mind.squeeze_radius`)."""
        return 2.0 * self.planning_radius

    def drive_time(self, distance: float) -> float:
        return abs(distance) / self.linear_speed

    def turn_time(self, angle: float) -> float:
        """Seconds to turn in place by `angle` the short way round."""
        wrapped = (angle + math.pi) % (2 * math.pi) - math.pi
        return abs(wrapped) / self.angular_speed

    def torso_time(self, delta: float) -> float:
        return 0.0 if delta == 0.0 else abs(delta) / self.torso_speed

    def head_time(self, delta_pan: float, delta_tilt: float) -> float:
        """Pan and tilt move together: the slower axis decides."""
        return max(abs(delta_pan) / self.pan_speed, abs(delta_tilt) / self.tilt_speed)
