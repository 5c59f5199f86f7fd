"""Navigable view poses for QSR search (Algorithm 1's NavigatablePoses): free cells where the
robot's footprint fits, within sensing range of a supporting plane, facing one of its voxels."""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from conceptual_map.metric import OccupancyGrid


def reachable(grid: OccupancyGrid, radius: float, start: tuple[float, float]) -> np.ndarray:
    """Traversable cells connected (8-neighbours) to the start's cell, or to the traversable
    cell nearest to it when the robot stands inside the inflation zone."""
    free = grid.traversable(radius)
    labels, _ = ndimage.label(free, structure=np.ones((3, 3), dtype=bool))
    cell = np.clip(grid.cell_of(start), 0, np.asarray(grid.shape) - 1)
    if not free[tuple(cell)]:
        _, nearest = ndimage.distance_transform_edt(~free, return_indices=True)
        cell = nearest[:, cell[0], cell[1]]
    return labels == labels[tuple(cell)] if free[tuple(cell)] else np.zeros_like(free)


def candidate_cells(
    grid: OccupancyGrid,
    points: np.ndarray,
    radius: float,
    max_range: float,
    start: tuple[float, float] | None = None,
) -> np.ndarray:
    """Cells (k, 2) traversable with `radius` (and reachable from `start` when given) whose
    distance to a plane voxel's column is at most `max_range` (one distance transform over the
    window around the planes)."""
    res = grid.resolution
    cells = grid.to_cell(points[:, :2])
    reach = int(math.ceil(max_range / res))
    lo = np.maximum(cells.min(axis=0) - reach, 0)
    hi = np.minimum(cells.max(axis=0) + reach + 1, np.asarray(grid.shape))
    if np.any(hi <= lo):
        return np.zeros((0, 2), dtype=np.int64)
    plane = np.zeros(tuple(hi - lo), dtype=bool)
    local = cells - lo
    ok = np.all((local >= 0) & (local < hi - lo), axis=1)
    plane[local[ok, 0], local[ok, 1]] = True
    near = ndimage.distance_transform_edt(~plane) * res <= max_range - res
    free = grid.traversable(radius) if start is None else reachable(grid, radius, start)
    free = free[lo[0] : hi[0], lo[1] : hi[1]]
    return np.argwhere(free & near) + lo


def sample_poses(
    grid: OccupancyGrid,
    points: np.ndarray,
    n: int,
    radius: float,
    max_range: float,
    rng: np.random.Generator,
    start: tuple[float, float] | None = None,
) -> np.ndarray:
    """Up to n poses (x, y, yaw) at distinct candidate cells, each facing a plane voxel within
    `max_range` chosen at random (so every pose looks at some support)."""
    cells = candidate_cells(grid, points, radius, max_range, start)
    if cells.shape[0] == 0:
        return np.zeros((0, 3))
    chosen = cells[rng.choice(cells.shape[0], size=min(n, cells.shape[0]), replace=False)]
    xy = grid.to_world(chosen)
    dx = points[None, :, 0] - xy[:, 0:1]
    dy = points[None, :, 1] - xy[:, 1:2]
    within = dx * dx + dy * dy <= max_range * max_range
    running = np.cumsum(within, axis=1, dtype=np.int32)
    pick = np.argmax(running > (rng.random(len(xy)) * running[:, -1])[:, None], axis=1)
    rows = np.arange(len(xy))
    yaw = np.arctan2(dy[rows, pick], dx[rows, pick])
    return np.column_stack([xy, yaw])
