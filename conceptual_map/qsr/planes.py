"""Supporting planes from the 3D voxel map (QSR paper §II-B, Fig. 4) and densities over their
voxels.

A voxel belongs to a supporting plane when it is occupied, the voxel above it is free and
nothing is occupied for `clearance` above that: an upward-facing surface, which is what the
QSR paper's averaged upward normals select. Connected surface voxels at table height form
segments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from conceptual_map.metric.voxels import VoxelMap
from conceptual_map.qsr.mixture import GaussianMixture

_CONNECTED = np.ones((3, 3, 3), dtype=bool)  # 26-neighbours: a keyboard joins its desk top


@dataclass(frozen=True)
class PlaneSegment:
    """One connected surface: its voxels (integer cells and world centres) and mean top height."""

    index: int
    height: float
    cells: np.ndarray
    points: np.ndarray
    resolution: float

    @property
    def area(self) -> float:
        """Square metres covered (one voxel face per surface voxel)."""
        return self.cells.shape[0] * self.resolution**2

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Outer extent (x0, y0, x1, y1) of the segment's voxels."""
        half = self.resolution / 2.0
        lo, hi = self.points[:, :2].min(axis=0) - half, self.points[:, :2].max(axis=0) + half
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


@dataclass(frozen=True)
class SupportingPlanes:
    """All supporting-plane voxels v_1..v_n (`points`, world centres) and their segments."""

    segments: tuple[PlaneSegment, ...]
    points: np.ndarray
    segment_of: np.ndarray
    resolution: float

    def __len__(self) -> int:
        return int(self.points.shape[0])

    def uniform_density(self) -> np.ndarray:
        """Equal probability on every plane voxel (the `supporting-planes` method)."""
        return np.full(len(self), 1.0 / len(self)) if len(self) else np.zeros(0)

    def density(self, mixture: GaussianMixture) -> np.ndarray:
        """P_QSR(v_i): the mixture's density at each voxel, normalised over the plane voxels
        (Fig. 5); all zeros when the mixture puts no mass anywhere near them."""
        values = mixture.pdf(self.points[:, :2]) if len(self) else np.zeros(0)
        total = values.sum()
        return values / total if total > 0.0 else np.zeros_like(values)


def extract_supporting_planes(
    voxels: VoxelMap,
    z_range: tuple[float, float] = (0.4, 1.2),
    clearance: float = 0.1,
    min_area: float = 0.04,
) -> SupportingPlanes:
    """Upward-facing occupied surfaces whose top lies in `z_range` (m), with `clearance` (m) of
    non-occupied space above (the first voxel above free), in segments of at least `min_area`."""
    res = voxels.resolution
    k0 = max(0, math.ceil((z_range[0] - voxels.origin[2]) / res) - 1)
    k1 = min(voxels.shape[2], math.floor((z_range[1] - voxels.origin[2]) / res))
    above = max(1, math.ceil(clearance / res))
    slab = voxels.logodds[:, :, k0 : min(voxels.shape[2], k1 + above)]
    occupied, free = slab >= voxels.model.occupied_at, slab <= voxels.model.free_at
    top = _surface(occupied, free, above)[:, :, : max(0, k1 - k0)]
    lo, hi = _bounding_box(top)
    labels, count = ndimage.label(top[lo[0] : hi[0], lo[1] : hi[1], lo[2] : hi[2]],
                                  structure=_CONNECTED)  # fmt: skip
    return _segments(voxels, labels, count, lo + [0, 0, k0], min_area)


def _bounding_box(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Smallest index box [lo, hi) holding every True cell (empty box when there is none)."""
    spans = []
    for axis in range(mask.ndim):
        hit = np.flatnonzero(mask.any(axis=tuple(a for a in range(mask.ndim) if a != axis)))
        spans.append((hit[0], hit[-1] + 1) if hit.size else (0, 0))
    return np.array([a for a, _ in spans]), np.array([b for _, b in spans])


def _surface(occupied: np.ndarray, free: np.ndarray, above: int) -> np.ndarray:
    """Occupied cells with a free cell on top and no occupied cell within `above` cells
    (the voxel map's own thresholds: occupied and free as `VoxelMap.states` classifies)."""
    top = occupied.copy()
    top[:, :, -1] = False
    top[:, :, :-1] &= free[:, :, 1:]
    for k in range(2, above + 1):
        top[:, :, :-k] &= ~occupied[:, :, k:]
    return top


def _segments(
    voxels: VoxelMap, labels: np.ndarray, count: int, offset: np.ndarray, min_area: float
) -> SupportingPlanes:
    res = voxels.resolution
    flat = np.flatnonzero(labels)
    cells_all = np.column_stack(np.unravel_index(flat, labels.shape)) + offset
    ids = labels.reshape(-1)[flat]
    order = np.argsort(ids, kind="stable")
    cells_all, ids = cells_all[order], ids[order]
    sizes = np.bincount(ids, minlength=count + 1)
    keep = sizes * res**2 >= min_area - 1e-12
    segments, chunks = [], []
    starts = np.concatenate([[0], np.cumsum(sizes[1:])])
    for label in np.flatnonzero(keep[1:]) + 1:
        cells = cells_all[starts[label - 1] : starts[label]]
        points = voxels.to_world(cells)
        height = float(points[:, 2].mean() + res / 2.0)
        segments.append(PlaneSegment(len(segments), height, cells, points, res))
        chunks.append(points)
    points = np.vstack(chunks) if chunks else np.zeros((0, 3))
    segment_of = np.concatenate(
        [np.full(len(s.cells), s.index) for s in segments] or [np.zeros(0, dtype=int)]
    )
    return SupportingPlanes(tuple(segments), points, segment_of.astype(np.int64), res)
