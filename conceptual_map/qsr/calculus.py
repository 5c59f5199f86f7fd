"""The ternary point calculus (Kunze et al., eq. 1): robot (origin), landmark (relatum), object.

The robot and the landmark define a reference axis; the object's relative angle to it names the
directional relation (behind 0, left pi/2, front pi, right 3pi/2) and its relative radius (distance
to the landmark over the robot's distance to the landmark) names the distance relation. As in the
seed, landmarks have a full pose: the robot is imagined standing in front of the landmark, facing
its intrinsic front side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Landmark:
    """A static object with a known pose; `facing` is the world heading of its intrinsic front."""

    label: str
    x: float
    y: float
    facing: float
    name: str = ""

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x, self.y])


def wrap_angle(angle: np.ndarray | float) -> np.ndarray | float:
    """Angles in [0, 2 pi)."""
    return np.mod(angle, TWO_PI)


def relative_angle(
    robot: np.ndarray, landmark: np.ndarray, obj: np.ndarray
) -> np.ndarray | float:
    """Eq. 1: angle of the object seen from the landmark minus the robot-to-landmark heading.

    Arrays broadcast over a leading axis ((N, 2) or (2,)); the result is in [0, 2 pi). The
    quadrant-aware arctangent replaces the QSR paper's tan^-1 of a quotient.
    """
    robot, landmark, obj = (np.asarray(a, dtype=float) for a in (robot, landmark, obj))
    to_obj = obj - landmark
    to_land = landmark - robot
    phi = np.arctan2(to_obj[..., 1], to_obj[..., 0]) - np.arctan2(to_land[..., 1], to_land[..., 0])
    return wrap_angle(phi)


def relative_radius(robot: np.ndarray, landmark: np.ndarray, obj: np.ndarray) -> np.ndarray:
    """|object - landmark| / |landmark - robot|: the QSR paper's ratio behind close and distant."""
    robot, landmark, obj = (np.asarray(a, dtype=float) for a in (robot, landmark, obj))
    return np.linalg.norm(obj - landmark, axis=-1) / np.linalg.norm(landmark - robot, axis=-1)


def virtual_robot(landmark: Landmark, distance: float) -> np.ndarray:
    """Where the QSR paper imagines the robot: `distance` metres in front of the landmark."""
    return landmark.xy + distance * np.array([math.cos(landmark.facing), math.sin(landmark.facing)])


def place_objects(
    robot: np.ndarray, relatum: np.ndarray, angle: np.ndarray, distance: np.ndarray
) -> np.ndarray:
    """Inverse of eq. 1: points at `distance` from each relatum (N, 2) at relative `angle` (N,)."""
    relatum = np.asarray(relatum, dtype=float)
    to_land = relatum - np.asarray(robot, dtype=float)
    heading = np.arctan2(to_land[..., 1], to_land[..., 0]) + angle
    offset = np.stack([np.cos(heading), np.sin(heading)], axis=-1) * distance[..., None]
    return relatum + offset


def nearest_direction(angle: float, means: dict[str, float]) -> str:
    """The directional relation whose mean angle is circularly closest to `angle`."""

    def gap(mean: float) -> float:
        d = abs(float(wrap_angle(angle - mean)))
        return min(d, TWO_PI - d)

    return min(means, key=lambda name: gap(means[name]))
