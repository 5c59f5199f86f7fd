"""Synthetic sensor data from axis-aligned boxes: for tests and benchmarks of the maps only.

Mapping code never calls this; it only stands in for a simulator when checking the maps
against a layout whose geometry is known exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class LaserScan:
    """Same attribute names as the executor's laser scans."""

    pose: tuple[float, float, float]
    angles: np.ndarray
    ranges: np.ndarray
    max_range: float
    height: float = 0.3
    time: float = 0.0


@dataclass(frozen=True)
class DepthFrame:
    """Same attribute names as the executor's depth frames."""

    origin: np.ndarray
    directions: np.ndarray
    ranges: np.ndarray
    max_range: float
    time: float = 0.0


@dataclass
class BoxWorld:
    """Obstacles as boxes (x0, y0, z0, x1, y1, z1); rays are cut where they first enter one."""

    boxes: list[tuple[float, float, float, float, float, float]] = field(default_factory=list)

    def add_box(self, x0: float, y0: float, x1: float, y1: float, z0=0.0, z1=2.0) -> None:
        self.boxes.append((min(x0, x1), min(y0, y1), z0, max(x0, x1), max(y0, y1), z1))

    def cast(self, origin: np.ndarray, dirs: np.ndarray, max_range: float) -> np.ndarray:
        """Distance to the first box along each unit direction (N, 3); inf beyond max_range."""
        if not self.boxes:
            return np.full(dirs.shape[0], np.inf)
        b = np.asarray(self.boxes, dtype=float)
        lo, hi = b[None, :, :3], b[None, :, 3:]
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / dirs[:, None, :]
            t1, t2 = (lo - origin) * inv, (hi - origin) * inv
        t1 = np.where(np.isnan(t1), -np.inf, t1)
        t2 = np.where(np.isnan(t2), np.inf, t2)
        near = np.minimum(t1, t2).max(axis=2)
        far = np.maximum(t1, t2).min(axis=2)
        t = np.where((far >= near) & (far > 0) & (near >= 0), near, np.inf).min(axis=1)
        return np.where(t < max_range, t, np.inf)

    def laser(
        self,
        pose: tuple[float, float, float],
        beams: int = 720,
        fov: float = 2 * np.pi,
        max_range: float = 5.6,
        height: float = 0.3,
    ) -> LaserScan:
        """A planar scan at `height`, beams spread evenly over `fov` centred on the heading."""
        if fov >= 2 * np.pi:
            angles = np.linspace(-np.pi, np.pi, beams, endpoint=False)
        else:
            angles = np.linspace(-fov / 2, fov / 2, beams)
        heading = pose[2] + angles
        dirs = np.stack([np.cos(heading), np.sin(heading), np.zeros_like(heading)], axis=1)
        origin = np.array([pose[0], pose[1], height])
        return LaserScan(tuple(pose), angles, self.cast(origin, dirs, max_range), max_range, height)

    def depth(
        self,
        origin: tuple[float, float, float],
        yaw: float,
        pitch: float = 0.0,
        size: tuple[int, int] = (64, 48),
        fov: tuple[float, float] = (1.0, 0.78),
        max_range: float = 4.0,
    ) -> DepthFrame:
        """A pinhole depth frame looking along (yaw, pitch), as world-frame rays."""
        u = np.tan(np.linspace(-fov[0] / 2, fov[0] / 2, size[0]))
        v = np.tan(np.linspace(-fov[1] / 2, fov[1] / 2, size[1]))
        uu, vv = np.meshgrid(u, v)
        cam = np.stack([np.ones(uu.size), -uu.ravel(), -vv.ravel()], axis=1)
        cam /= np.linalg.norm(cam, axis=1, keepdims=True)
        dirs = cam @ _rotation(yaw, pitch).T
        origin_a = np.asarray(origin, dtype=float)
        return DepthFrame(origin_a, dirs, self.cast(origin_a, dirs, max_range), max_range)


def _rotation(yaw: float, pitch: float) -> np.ndarray:
    cy, sy, cp, sp = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch)
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0], [sp, 0.0, cp]])
    return rz @ ry


def rooms_world(
    rooms: list[tuple[float, float, float, float]],
    doors: list[tuple[float, float, float]],
    wall: float = 0.12,
    height: float = 2.0,
) -> BoxWorld:
    """Walls on every room border, with a gap of `width` at each door (x, y, width).

    A door is cut out of whichever wall segment passes through its centre.
    """
    world = BoxWorld()
    segments: set[tuple[float, float, float, float]] = set()
    for x0, y0, x1, y1 in rooms:
        segments |= {(x0, y0, x1, y0), (x0, y1, x1, y1), (x0, y0, x0, y1), (x1, y0, x1, y1)}
    gaps = [(x, y, width + wall) for x, y, width in doors]  # boxes overhang by wall / 2
    for x0, y0, x1, y1 in sorted(segments):
        for a, b in _cut(x0, y0, x1, y1, gaps):
            half = wall / 2
            world.add_box(a[0] - half, a[1] - half, b[0] + half, b[1] + half, 0.0, height)
    return world


def _cut(x0, y0, x1, y1, doors):  # noqa: ANN001, ANN202 - small geometric helper
    horizontal = y0 == y1
    lo, hi = (x0, x1) if horizontal else (y0, y1)
    pieces = [(lo, hi)]
    for dx, dy, width in doors:
        on_line = abs((dy if horizontal else dx) - (y0 if horizontal else x0)) < 1e-9
        centre = dx if horizontal else dy
        if not on_line or not lo < centre < hi:
            continue
        pieces = [
            p
            for a, b in pieces
            for p in ((a, min(b, centre - width / 2)), (max(a, centre + width / 2), b))
            if p[1] > p[0]
        ]
    if horizontal:
        return [((a, y0), (b, y0)) for a, b in pieces]
    return [((x0, a), (x0, b)) for a, b in pieces]
