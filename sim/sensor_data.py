"""What the sensors hand over: frozen dataclasses of numpy arrays, in the world frame.

These shapes are agreed with the mapping code, which builds maps from them without importing
`sim`: keep the attribute names. Times are simulated seconds on the robot's clock.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LaserScan:
    """A planar scan: beam `angles` relative to the heading, `ranges` (np.inf = no hit)."""

    pose: tuple[float, float, float]  # sensor x, y, yaw in the world
    angles: np.ndarray  # (N,) radians relative to the robot heading
    ranges: np.ndarray  # (N,) metres, np.inf where nothing was hit within max_range
    max_range: float
    height: float  # sensor height above the floor
    time: float

    def points(self) -> np.ndarray:
        """(M, 2) world-frame hit points of the finite beams."""
        x, y, yaw = self.pose
        hit = np.isfinite(self.ranges)
        a = self.angles[hit] + yaw
        r = self.ranges[hit]
        return np.column_stack([x + r * np.cos(a), y + r * np.sin(a)])


@dataclass(frozen=True)
class CameraView:
    """Where the camera looked: origin, heading (yaw), pitch (up positive), FOVs, range."""

    origin: np.ndarray  # (3,) world frame
    yaw: float
    pitch: float
    hfov: float
    vfov: float
    max_range: float

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: which (N, 3) world points lie inside the view frustum."""
        d = np.atleast_2d(points) - self.origin
        cy, sy = np.cos(self.yaw), np.sin(self.yaw)
        cp, sp = np.cos(self.pitch), np.sin(self.pitch)
        fwd_h = cy * d[:, 0] + sy * d[:, 1]
        left = -sy * d[:, 0] + cy * d[:, 1]
        forward = cp * fwd_h + sp * d[:, 2]
        up = -sp * fwd_h + cp * d[:, 2]
        dist = np.linalg.norm(d, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            in_h = np.abs(np.arctan2(left, forward)) <= self.hfov / 2
            in_v = np.abs(np.arctan2(up, forward)) <= self.vfov / 2
        return (forward > 0) & in_h & in_v & (dist <= self.max_range)


@dataclass(frozen=True)
class DepthScan:
    """Depth rays from the camera: unit `directions` and `ranges` (np.inf = no hit)."""

    origin: np.ndarray  # (3,) camera position, world frame
    directions: np.ndarray  # (N, 3) unit vectors, world frame
    ranges: np.ndarray  # (N,) metres, np.inf where nothing was hit within max_range
    max_range: float
    time: float
    view: CameraView

    def points(self) -> np.ndarray:
        """(M, 3) world-frame hit points of the finite rays."""
        hit = np.isfinite(self.ranges)
        return self.origin + self.directions[hit] * self.ranges[hit, None]


@dataclass(frozen=True)
class Detection:
    """One recognised thing: label, noisy world position, confidence, and the view it came from.

    `truth_name` names the world entry it came from (None for a false positive); it exists only
    for evaluating episodes and must not be read by planning or mapping code.
    """

    label: str
    position: np.ndarray  # (3,) world-frame estimate of the object's centre
    confidence: float
    time: float
    view: CameraView
    visible_fraction: float
    truth_name: str | None = None


@dataclass(frozen=True)
class DetectionFrame:
    """The result of one `detect()`: the view looked at (useful even when nothing was seen)."""

    view: CameraView
    detections: tuple[Detection, ...]
    time: float
    queried: tuple[str, ...] | None  # labels asked for, None = every label

    def __iter__(self) -> Iterator[Detection]:
        return iter(self.detections)

    def __len__(self) -> int:
        return len(self.detections)

    def labels(self) -> list[str]:
        return [d.label for d in self.detections]


@dataclass(frozen=True)
class PlaceObservation:
    """The place-appearance classifier's output: the category it saw and P(seen | category)."""

    observed: str
    likelihood: dict[str, float]  # for every category c: P(observed | true category c)
    time: float
