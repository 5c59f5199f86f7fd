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


def line_of_sight(
    voxels,  # noqa: ANN001 - a conceptual_map VoxelMap
    origins: np.ndarray,
    points: np.ndarray,
    pairs: np.ndarray | None = None,
    skip: float = 0.15,
    chunk: int = 4096,
) -> np.ndarray:
    """(n, m) mask: no occupied voxel of `voxels` lies on the segment from origin i (x, y, z)
    to point j, apart from its last `skip` metres (the surface the point lies on: a ray that
    grazes a table top crosses the top's own voxels just before it). Unknown voxels do not
    block. Only the pairs set in `pairs` (n, m) are tested; the others stay False."""
    n, m = len(origins), len(points)
    out = np.zeros((n, m), dtype=bool)
    todo = np.argwhere(np.ones((n, m), dtype=bool) if pairs is None else pairs)
    if len(todo) == 0:
        return out
    res = voxels.resolution
    origin = np.asarray(voxels.origin, dtype=np.float32)
    shape = np.asarray(voxels.shape)
    occupied = (voxels.logodds >= voxels.model.occupied_at).ravel()
    strides = np.array([shape[1] * shape[2], shape[2], 1], dtype=np.int64)
    step = res  # one sample per voxel length: a blocking wall or monitor is thicker than that
    for lo in range(0, len(todo), chunk):
        part = todo[lo : lo + chunk]
        a = origins[part[:, 0]].astype(np.float32)
        b = points[part[:, 1]].astype(np.float32)
        length = np.linalg.norm(b - a, axis=1)
        reach = np.maximum(length - skip, 0.0)
        count = int(np.ceil(reach.max() / step)) + 1
        s = np.arange(count, dtype=np.float32) * np.float32(step)  # metres along each segment
        direction = (b - a) / np.maximum(length, 1e-9)[:, None]
        cells = np.floor((a[:, None, :] - origin + s[None, :, None] * direction[:, None, :])
                         / np.float32(res)).astype(np.int64)
        inside = (s[None, :] <= reach[:, None]) & np.all((cells >= 0) & (cells < shape), axis=2)
        flat = np.where(inside, cells @ strides, 0)
        hit = occupied[flat] & inside
        out[part[:, 0], part[:, 1]] = ~hit.any(axis=1)
    return out
