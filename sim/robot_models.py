"""The two robot models: geometry, joint limits, sensor parameters and time model of each.

Numbers follow the papers: a Pioneer III with a laser and a camera 1.4 m high on a pan-tilt unit
(§4 of the active visual search paper by Göbelbecker et al.), and a PR2 with a 0.31 m telescoping
torso, head pan 350° and tilt 115° (§4 of the FLAP paper by Gedicke et al.).
Speeds are nominal values of the real platforms, not measurements.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from sim.time_model import TimeModel

ROBOTS_DIR = Path(__file__).parent / "robots"


@dataclass(frozen=True)
class Limits:
    """A closed joint range [low, high] in metres or radians."""

    low: float
    high: float

    def contains(self, value: float) -> bool:
        return self.low - 1e-9 <= value <= self.high + 1e-9


@dataclass(frozen=True)
class LaserSpec:
    """A planar laser: field of view centred on the heading, beam count, range, noise."""

    fov: float
    beams: int
    max_range: float
    noise_sigma: float = 0.01


@dataclass(frozen=True)
class CameraSpec:
    """The head camera: field of view, depth range, and the range objects can be recognised at."""

    hfov: float
    vfov: float
    depth_range: float
    detect_range: float
    depth_noise_sigma: float = 0.01


@dataclass(frozen=True)
class RobotModel:
    """Everything the adapter needs to know about a robot type."""

    name: str
    urdf: Path
    footprint_radius: float  # collision circle of the base
    holonomic: bool
    torso: Limits
    pan: Limits
    tilt: Limits
    laser: LaserSpec
    camera: CameraSpec
    time: TimeModel


PIONEER = RobotModel(
    name="pioneer",
    urdf=ROBOTS_DIR / "pioneer.urdf",
    footprint_radius=0.26,
    holonomic=False,
    torso=Limits(0.0, 0.0),
    pan=Limits(math.radians(-159.0), math.radians(159.0)),
    tilt=Limits(math.radians(-47.0), math.radians(31.0)),
    laser=LaserSpec(fov=math.radians(240.0), beams=241, max_range=5.6),
    camera=CameraSpec(hfov=math.radians(60.0), vfov=math.radians(45.0), depth_range=5.0,
                      detect_range=4.0),
    time=TimeModel(linear_speed=0.5, angular_speed=1.0, torso_speed=1.0, pan_speed=1.0,
                   tilt_speed=1.0, scan_time=0.1, sensing_time=0.5),
)

PR2 = RobotModel(
    name="pr2",
    urdf=ROBOTS_DIR / "pr2.urdf",
    footprint_radius=0.34,
    holonomic=True,
    torso=Limits(0.0, 0.31),
    pan=Limits(math.radians(-175.0), math.radians(175.0)),
    tilt=Limits(math.radians(-60.0), math.radians(55.0)),
    laser=LaserSpec(fov=math.radians(270.0), beams=271, max_range=10.0),
    camera=CameraSpec(hfov=math.radians(58.0), vfov=math.radians(45.0), depth_range=4.5,
                      detect_range=3.5),
    time=TimeModel(linear_speed=0.5, angular_speed=0.8, torso_speed=0.015, pan_speed=2.0,
                   tilt_speed=2.0, scan_time=0.1, sensing_time=1.0),
)

ROBOT_MODELS: dict[str, RobotModel] = {m.name: m for m in (PIONEER, PR2)}
