"""Optimistic ray casting (FLAP §3.1): which unknown region cells a virtual camera would see.

Rays pass through free and unknown cells and stop at the first occupied one; unknown region
cells they cross are "expected visible". Rays are cast only into the part of the field of view
that the region's boxes within range cover, so a fixed ray count gives dense rays on the
region, and each ray is marched only until it leaves the last box it crosses. All views of a
batch are marched at once with numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_SHIFT = 4096  # cells; makes integer truncation a floor for any point near the map
_CHUNKS = 4  # rays are marched in this many groups of similar length
_CORNERS = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=bool)
OCCUPIED = -2  # lookup code of an occupied map cell; region cells carry their index >= 0


@dataclass(frozen=True)
class Cameras:
    """A batch of camera poses: origins (V, 3), yaw and pitch (V,) of the optical axis."""

    origins: np.ndarray
    yaw: np.ndarray
    pitch: np.ndarray


@dataclass(frozen=True)
class CastGrid:
    """The map the rays march through: per-cell code (OCCUPIED, -1 pass, >= 0 region cell)."""

    codes: np.ndarray  # flat, one entry per voxel
    shape: tuple[int, int, int]
    origin: np.ndarray
    resolution: float
    region_lo: np.ndarray  # (k, 3) world corners of the region's boxes (the target volumes)
    region_hi: np.ndarray


def visible_cells(
    grid: CastGrid,
    cams: Cameras,
    fov: tuple[float, float],
    max_range: float,
    rays: tuple[int, int] = (24, 18),
    step: float = 0.7,
) -> list[np.ndarray]:
    """Sorted region indices each camera would see (optimistic); `step` is in cells."""
    n_views = cams.origins.shape[0]
    dirs = _ray_directions(grid, cams, fov, rays, max_range)  # (V, R, 3)
    t_end = _exit_distance(grid, cams.origins, dirs, max_range).reshape(-1)
    view = np.repeat(np.arange(n_views), dirs.shape[1])
    live = np.nonzero(t_end > 0)[0]
    live = live[np.argsort(t_end[live])]  # similar lengths march together
    width = max(1, int(grid.codes.max()) + 1)
    hit = np.zeros(n_views * width, dtype=bool)  # (view, region cell) pairs seen
    for chunk in np.array_split(live, _CHUNKS) if live.size else []:
        codes, seen = _march(grid, cams.origins[view[chunk]], dirs.reshape(-1, 3)[chunk],
                             t_end[chunk], step * grid.resolution)
        hit[view[chunk][:, None].repeat(codes.shape[1], 1)[seen] * width + codes[seen]] = True
    return _split_by_view(np.flatnonzero(hit), width, n_views)


def _march(
    grid: CastGrid, origins: np.ndarray, dirs: np.ndarray, t_end: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray]:
    """Codes (N, S) sampled every h metres along each ray, and which samples it sees."""
    steps = int(np.ceil(t_end.max() / h)) if t_end.size else 0
    t = (np.arange(steps, dtype=np.float32) + 0.5) * np.float32(h)
    if _inside_map(grid, origins):  # then every sample up to the region's exit is too
        codes = _sample_codes_inside(grid, origins, dirs, np.minimum(t[None, :], t_end[:, None]))
    else:
        codes = _sample_codes(grid, origins, dirs, t)
    blocked = np.logical_or.accumulate(codes == OCCUPIED, axis=1)
    return codes, (t[None, :] < t_end[:, None]) & ~blocked & (codes >= 0)


def _split_by_view(keys: np.ndarray, width: int, n_views: int) -> list[np.ndarray]:
    """Distinct region indices per view from sorted keys view * width + index."""
    bounds = np.searchsorted(keys // width, np.arange(n_views + 1))
    return [(keys[bounds[k] : bounds[k + 1]] % width).astype(np.int32) for k in range(n_views)]


def _ray_directions(
    grid: CastGrid,
    cams: Cameras,
    fov: tuple[float, float],
    rays: tuple[int, int],
    max_range: float,
) -> np.ndarray:
    """Unit ray directions (V, R, 3) over the part of the field of view the region covers."""
    az_lo, az_hi, el_lo, el_hi = _region_window(grid, cams, fov, max_range)
    u = np.linspace(0.0, 1.0, rays[0], dtype=np.float32)
    v = np.linspace(0.0, 1.0, rays[1], dtype=np.float32)
    uu, vv = (a.ravel() for a in np.meshgrid(u, v))
    az = az_lo[:, None] + (az_hi - az_lo)[:, None] * uu[None, :]
    el = el_lo[:, None] + (el_hi - el_lo)[:, None] * vv[None, :]
    local = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1)
    return np.matmul(local, _rotations(cams).transpose(0, 2, 1)).astype(np.float32)


def _rotations(cams: Cameras) -> np.ndarray:
    """Camera-to-world rotations (V, 3, 3): x forward along (yaw, pitch), z up."""
    cy, sy = np.cos(cams.yaw), np.sin(cams.yaw)
    cp, sp = np.cos(cams.pitch), np.sin(cams.pitch)
    zero = np.zeros_like(cy)
    forward = np.stack([cp * cy, cp * sy, sp], axis=-1)
    left = np.stack([-sy, cy, zero], axis=-1)
    up = np.stack([-sp * cy, -sp * sy, cp], axis=-1)
    return np.stack([forward, left, up], axis=-1)


def _region_window(
    grid: CastGrid, cams: Cameras, fov: tuple[float, float], max_range: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Azimuth and elevation limits (camera frame) of the boxes within range, clipped to the
    fov. A camera that has such a box partly behind it (x <= 0 in its frame) keeps the full fov.
    """
    lo, hi = grid.region_lo, grid.region_hi  # (k, 3)
    corners = np.where(_CORNERS[None, :, :], hi[:, None, :], lo[:, None, :])  # (k, 8, 3)
    rel = corners[None] - cams.origins[:, None, None, :]
    local = np.matmul(rel, _rotations(cams)[:, None])  # world -> camera, (V, k, 8, 3)
    nearest = np.clip(cams.origins[:, None, :], lo[None], hi[None])
    near = np.linalg.norm(nearest - cams.origins[:, None, :], axis=2) <= max_range  # (V, k)
    whole = np.any(near & ~np.all(local[..., 0] > 1e-3, axis=2), axis=1)
    az = np.arctan2(local[..., 1], local[..., 0])
    el = np.arctan2(local[..., 2], np.hypot(local[..., 0], local[..., 1]))
    half_h, half_v = fov[0] / 2, fov[1] / 2

    def span(angle: np.ndarray, half: float) -> tuple[np.ndarray, np.ndarray]:
        low = np.where(near[..., None], angle, np.inf).min(axis=(1, 2))
        high = np.where(near[..., None], angle, -np.inf).max(axis=(1, 2))
        low = np.where(whole | ~near.any(axis=1), -half, np.clip(low, -half, half))
        high = np.where(whole | ~near.any(axis=1), half, np.clip(high, -half, half))
        return low, high

    return *span(az, half_h), *span(el, half_v)


def _exit_distance(
    grid: CastGrid, origins: np.ndarray, dirs: np.ndarray, max_range: float
) -> np.ndarray:
    """Distance (V, R) along each ray to where it leaves the last box it crosses (0 if it
    crosses none), capped at range."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / dirs[:, :, None, :]
        t1 = (grid.region_lo[None, None] - origins[:, None, None, :]) * inv
        t2 = (grid.region_hi[None, None] - origins[:, None, None, :]) * inv
    t1 = np.where(np.isnan(t1), -np.inf, t1)
    t2 = np.where(np.isnan(t2), np.inf, t2)
    near = np.minimum(t1, t2).max(axis=3)
    far = np.maximum(t1, t2).min(axis=3)  # (V, R, k)
    far = np.where(far >= np.maximum(near, 0.0), far, 0.0).max(axis=2)
    return np.minimum(far, max_range).astype(np.float32)


def _inside_map(grid: CastGrid, points: np.ndarray) -> bool:
    cells = np.floor((points - grid.origin) / grid.resolution)
    return bool(np.all((cells >= 0) & (cells < np.asarray(grid.shape))))


def _sample_codes_inside(
    grid: CastGrid, origins: np.ndarray, dirs: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """Lookup codes (N, S) at distances t (N, S) along rays whose samples all lie in the map
    (segments from a camera inside the map to points of the region box, which is too)."""
    scale = np.float32(1.0 / grid.resolution)
    start = ((origins - grid.origin) * scale).astype(np.float32)
    ts = t * scale
    flat = np.zeros(t.shape, dtype=np.int32)
    stride = 1
    for axis in (2, 1, 0):
        cell = (start[:, None, axis] + dirs[:, None, axis] * ts).astype(np.int32)
        np.minimum(cell, grid.shape[axis] - 1, out=cell)  # a point on the far face
        cell *= stride
        flat += cell
        stride *= grid.shape[axis]
    return grid.codes[flat]


def _sample_codes(
    grid: CastGrid, origins: np.ndarray, dirs: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """Lookup codes (N, S) of the cells at distances t along every ray; -1 off the map."""
    scale = np.float32(1.0 / grid.resolution)
    start = ((origins - grid.origin) * scale + _SHIFT).astype(np.float32)
    ts = t * scale
    flat = np.zeros((dirs.shape[0], t.size), dtype=np.int32)
    inside = np.ones(flat.shape, dtype=bool)
    stride = 1
    for axis in (2, 1, 0):
        coord = start[:, None, axis] + dirs[:, None, axis] * ts[None, :]
        cell = coord.astype(np.int32)  # truncation is floor: the shift keeps coord positive
        cell -= _SHIFT
        inside &= (cell >= 0) & (cell < grid.shape[axis])
        cell *= stride
        flat += cell
        stride *= grid.shape[axis]
    flat[~inside] = 0
    codes = grid.codes[flat]
    codes[~inside] = -1
    return codes
