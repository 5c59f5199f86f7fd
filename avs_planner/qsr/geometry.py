"""Vectorised visibility tests of the QSR view planner: 2D view cones and 3D frustums.

Like the seed's In(v, Viewcone(psi)), these are pure field-of-view and range tests over voxel
centres (no occlusion), evaluated for all poses or frustums against all voxels in one pass.
"""

from __future__ import annotations

import numpy as np


def in_view_cones(
    poses: np.ndarray, points: np.ndarray, half_angle: float, max_range: float
) -> np.ndarray:
    """(n, m) mask: point j lies in the 2D cone of pose i (x, y, yaw), within `max_range`.

    The angle test is a dot product: the offset along the heading is at least distance times
    cos(half_angle) (no arctangent per pair).
    """
    dx = points[None, :, 0] - poses[:, 0:1]
    dy = points[None, :, 1] - poses[:, 1:2]
    along = dx * np.cos(poses[:, 2:3]) + dy * np.sin(poses[:, 2:3])
    dist = np.sqrt(dx * dx + dy * dy)
    return (dist <= max_range) & (along >= dist * np.cos(half_angle) - 1e-12)


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
