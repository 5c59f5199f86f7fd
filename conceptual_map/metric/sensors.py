"""Shapes of the sensor data the maps accept (duck typed), and their validation.

The executor hands over objects with these attributes; the simulator's own classes fit
without importing them, and tests write small dataclasses with the same names.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from conceptual_map.metric.errors import SensorDataError


class LaserScanLike(Protocol):
    """A planar laser scan: sensor pose (x, y, yaw), beam angles relative to the heading."""

    pose: tuple[float, float, float]
    angles: np.ndarray
    ranges: np.ndarray
    max_range: float
    height: float
    time: float


class DepthFrameLike(Protocol):
    """A depth frame as rays: camera origin and unit directions in the world frame."""

    origin: np.ndarray
    directions: np.ndarray
    ranges: np.ndarray
    max_range: float
    time: float


@dataclass(frozen=True)
class Rays:
    """Validated rays in the world frame: where each starts, where it ends, whether it hit."""

    starts: np.ndarray  # (N, D)
    ends: np.ndarray  # (N, D)
    hit: np.ndarray  # (N,) bool: the end point is an obstacle surface


def laser_rays(scan: LaserScanLike) -> Rays:
    """Turn a laser scan into 2D rays; `inf` (or beyond max range) means free up to max range."""
    angles = _vector(scan.angles, "angles")
    ranges = _vector(scan.ranges, "ranges")
    if angles.shape != ranges.shape:
        raise SensorDataError(
            f"laser scan: angles has {angles.size} entries but ranges has {ranges.size}"
        )
    pose = np.asarray(scan.pose, dtype=float)
    if pose.shape != (3,) or not np.all(np.isfinite(pose)):
        raise SensorDataError(f"laser scan: pose must be three finite numbers, got {scan.pose!r}")
    heading = pose[2] + angles
    dirs = np.stack([np.cos(heading), np.sin(heading)], axis=1)
    return _rays(np.broadcast_to(pose[:2], dirs.shape), dirs, ranges, scan.max_range, "laser")


def depth_rays(frame: DepthFrameLike) -> Rays:
    """Turn a depth frame into 3D rays; `inf` (or beyond max range) means free up to max range."""
    origin = np.asarray(frame.origin, dtype=float)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise SensorDataError(f"depth frame: origin must be three finite numbers, got {origin!r}")
    dirs = np.asarray(frame.directions, dtype=float)
    ranges = _vector(frame.ranges, "ranges")
    if dirs.ndim != 2 or dirs.shape[1] != 3 or dirs.shape[0] != ranges.size:
        raise SensorDataError(
            f"depth frame: directions must be ({ranges.size}, 3), got {dirs.shape}"
        )
    norms = np.linalg.norm(dirs, axis=1)
    if np.any(np.abs(norms - 1.0) > 1e-3):
        raise SensorDataError("depth frame: directions must be unit vectors")
    return _rays(np.broadcast_to(origin, dirs.shape), dirs, ranges, frame.max_range, "depth")


def _vector(values: object, name: str) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise SensorDataError(f"{name} must be a 1-D array, got shape {array.shape}")
    return array


def _rays(
    starts: np.ndarray, dirs: np.ndarray, ranges: np.ndarray, max_range: float, what: str
) -> Rays:
    if not np.isfinite(max_range) or max_range <= 0:
        raise SensorDataError(f"{what}: max_range must be a positive number, got {max_range!r}")
    if np.any(ranges < 0):
        raise SensorDataError(f"{what}: ranges must not be negative")
    keep = ~np.isnan(ranges)
    hit = np.isfinite(ranges) & (ranges < max_range)
    length = np.where(hit, ranges, max_range)
    starts, dirs, length, hit = starts[keep], dirs[keep], length[keep], hit[keep]
    return Rays(np.array(starts), starts + dirs * length[:, None], hit)
