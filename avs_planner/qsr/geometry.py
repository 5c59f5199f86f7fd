"""Vectorised visibility tests of the QSR view planner: 2D view cones and 3D frustums.

Like the seed's In(v, Viewcone(psi)), these are pure field-of-view and range tests over voxel
centres (no occlusion), evaluated for all poses or frustums against all voxels in one pass.
"""

from __future__ import annotations

import numpy as np


def in_view_cones(
    poses: np.ndarray, points: np.ndarray, half_angle: float, max_range: float
) -> np.ndarray:
    """(n, m) mask: point j lies in the 2D cone of pose i (x, y, yaw), within `max_range`."""
    d = points[None, :, :2] - poses[:, None, :2]
    dist = np.hypot(d[..., 0], d[..., 1])
    bearing = np.arctan2(d[..., 1], d[..., 0]) - poses[:, 2:3]
    off = np.abs((bearing + np.pi) % (2.0 * np.pi) - np.pi)
    return (dist <= max_range) & (off <= half_angle)


def in_frustums(
    camera: np.ndarray,
    headings: np.ndarray,
    tilts: np.ndarray,
    points: np.ndarray,
    fov: tuple[float, float],
    max_range: float,
) -> np.ndarray:
    """(f, m) mask: point j (x, y, z) lies in frustum i, a pinhole view from `camera` (3,)
    along world heading `headings[i]` tilted by `tilts[i]` (negative looks down)."""
    ca, sa, ct, st = np.cos(headings), np.sin(headings), np.cos(tilts), np.sin(tilts)
    forward = np.stack([ct * ca, ct * sa, st], axis=1)
    left = np.stack([-sa, ca, np.zeros_like(ca)], axis=1)
    up = np.stack([-st * ca, -st * sa, ct], axis=1)
    rel = points - camera
    xf, xl, xu = forward @ rel.T, left @ rel.T, up @ rel.T
    inside = (xf > 0.0) & (np.abs(xl) <= xf * np.tan(fov[0] / 2.0))
    inside &= np.abs(xu) <= xf * np.tan(fov[1] / 2.0)
    return inside & (np.einsum("mi,mi->m", rel, rel)[None, :] <= max_range**2)
