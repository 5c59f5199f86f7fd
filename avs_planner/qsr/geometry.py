"""Vectorised visibility tests of the QSR view planner: 2D view cones and 3D frustums.

Like the QSR paper's In(v, Viewcone(psi)), these are pure field-of-view and range tests over voxel
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
    chunk: int = 8192,
) -> np.ndarray:
    """(n, m) mask: no occupied voxel of `voxels` lies on the segment from origin i (x, y, z)
    to point j, apart from its last `skip` metres (the surface the point lies on: a ray that
    grazes a table top crosses the top's own voxels just before it). Unknown voxels do not
    block, nor does anything outside the map. Only the pairs set in `pairs` (n, m) are tested;
    the others stay False.

    Each segment is sampled once per voxel length (a blocking wall or monitor is thicker than
    that). The work is vectorised over all pairs at once: the occupancy is cut to the box around
    the segments (a segment never leaves the box of its end points, so no sample needs a bounds
    test), the pairs are sorted by length so that a chunk's samples are not padded out to the
    longest segment, and a segment's samples past its end repeat its last one instead of being
    masked.
    """
    n, m = len(origins), len(points)
    out = np.zeros((n, m), dtype=bool)
    todo = np.argwhere(np.ones((n, m), dtype=bool) if pairs is None else pairs)
    if len(todo) == 0:
        return out
    res = float(voxels.resolution)
    grid_origin = np.asarray(voxels.origin, dtype=float)
    origins, points = np.asarray(origins, dtype=float), np.asarray(points, dtype=float)
    # everything in cell units, relative to the box around the used end points with one cell
    # to spare on every side: a sample's coordinates are then positive (truncation is floor)
    # and a rounding error can only land in the spare, unoccupied cells
    used = np.zeros(n, dtype=bool), np.zeros(m, dtype=bool)
    used[0][todo[:, 0]], used[1][todo[:, 1]] = True, True
    ends = np.vstack([origins[used[0]], points[used[1]]])
    lo = np.floor((ends.min(axis=0) - grid_origin) / res).astype(np.int64) - 1
    hi = np.floor((ends.max(axis=0) - grid_origin) / res).astype(np.int64) + 2
    flat_occupied = _occupied_box(voxels, lo, hi).ravel()
    box = hi - lo
    base = grid_origin + lo * res
    a_all = ((origins[todo[:, 0]] - base) / res).astype(np.float32)
    b_all = ((points[todo[:, 1]] - base) / res).astype(np.float32)
    length = np.linalg.norm(b_all - a_all, axis=1)  # cells
    last = np.floor(np.maximum(length - skip / res, 0.0)).astype(np.int64)  # last sample index
    order = np.argsort(last, kind="stable")
    direction = (b_all - a_all) / np.maximum(length, 1e-9)[:, None]  # one cell per step
    strides = np.array([box[1] * box[2], box[2], 1], dtype=np.int32)
    for start in range(0, len(order), chunk):
        rows = order[start : start + chunk]
        count = int(last[rows[-1]]) + 1
        k = np.minimum(np.arange(count, dtype=np.float32)[None, :],
                       last[rows, None].astype(np.float32))  # fmt: skip
        flat = np.zeros((len(rows), count), dtype=np.int32)
        for axis in range(3):
            cell = (a_all[rows, axis, None] + k * direction[rows, axis, None]).astype(np.int32)
            flat += cell * strides[axis]
        blocked = flat_occupied[flat].any(axis=1)
        out[todo[rows, 0], todo[rows, 1]] = ~blocked
    return out


def _occupied_box(voxels, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:  # noqa: ANN001
    """Occupied cells of the index box [lo, hi) (cells outside the map are not occupied)."""
    shape = np.asarray(voxels.shape, dtype=np.int64)
    out = np.zeros(tuple(hi - lo), dtype=bool)
    src_lo, src_hi = np.maximum(lo, 0), np.minimum(hi, shape)
    if np.any(src_hi <= src_lo):
        return out
    part = voxels.logodds[src_lo[0] : src_hi[0], src_lo[1] : src_hi[1], src_lo[2] : src_hi[2]]
    dst = src_lo - lo
    out[dst[0] : dst[0] + part.shape[0], dst[1] : dst[1] + part.shape[1],
        dst[2] : dst[2] + part.shape[2]] = part >= voxels.model.occupied_at  # fmt: skip
    return out
