"""Reachable frontier regions of the 2D grid: where placeholders go (seed 003 §2, §3).

A region is a connected group of frontier cells (unknown next to free) close to the free space
the robot can reach; it counts only if enough unknown space lies behind it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.logodds import CellState
from conceptual_map.places.config import PlaceMapConfig

_EIGHT = np.ones((3, 3), dtype=bool)


@dataclass(frozen=True)
class FrontierRegion:
    """One frontier region: a standing point in reachable space and what lies behind."""

    standpoint: tuple[float, float]
    centre: tuple[float, float]
    length: float  # metres of frontier (cell count x resolution)
    open_space: float  # m^2 of connected unknown within the configured radius


def reachable_mask(grid: OccupancyGrid, robot: tuple[float, float], radius: float) -> np.ndarray:
    """Traversable cells connected to the robot (or to the traversable cell nearest to it)."""
    traversable = grid.traversable(radius)
    if not traversable.any():
        return traversable
    labels, _ = ndimage.label(traversable, structure=_EIGHT)
    cell = grid.cell_of(robot)
    if not grid.contains(cell) or not traversable[cell]:
        _, idx = ndimage.distance_transform_edt(~traversable, return_indices=True)
        cell = _clip(grid, cell)
        cell = (int(idx[0][cell]), int(idx[1][cell]))
    return labels == labels[cell]


def _clip(grid: OccupancyGrid, cell: tuple[int, int]) -> tuple[int, int]:
    return (min(max(cell[0], 0), grid.shape[0] - 1), min(max(cell[1], 0), grid.shape[1] - 1))


def frontier_regions(
    grid: OccupancyGrid, robot: tuple[float, float], config: PlaceMapConfig
) -> list[FrontierRegion]:
    """All reachable frontier regions with at least `min_open_space` unknown behind them."""
    reachable = reachable_mask(grid, robot, config.robot_radius)
    if not reachable.any():
        return []
    far, nearest = ndimage.distance_transform_edt(~reachable, return_indices=True)
    frontier = grid.frontier_mask() & (far * grid.resolution <= config.reach_tolerance)
    labels, count = ndimage.label(frontier, structure=_EIGHT)
    unknown_labels, _ = ndimage.label(grid.state_grid() == CellState.UNKNOWN)
    regions = []
    for cells in _groups(labels, count):
        if cells.shape[0] * grid.resolution < config.min_frontier_length:
            continue
        region = _describe(grid, cells, nearest, unknown_labels, config)
        if region.open_space >= config.min_open_space:
            regions.append(region)
    return regions


def _groups(labels: np.ndarray, count: int) -> list[np.ndarray]:
    """Cell coordinates of each labelled group, without scanning the grid once per label."""
    flat = labels.ravel()
    order = np.argsort(flat, kind="stable")
    bounds = np.searchsorted(flat[order], np.arange(1, count + 2))
    coords = np.stack(np.unravel_index(order, labels.shape), axis=1)
    return [coords[bounds[k] : bounds[k + 1]] for k in range(count)]


def _describe(
    grid: OccupancyGrid,
    cells: np.ndarray,
    nearest: np.ndarray,
    unknown_labels: np.ndarray,
    config: PlaceMapConfig,
) -> FrontierRegion:
    medoid = cells[np.argmin(np.linalg.norm(cells - cells.mean(axis=0), axis=1))]
    stand = (int(nearest[0][tuple(medoid)]), int(nearest[1][tuple(medoid)]))
    standpoint = grid.to_world(np.asarray([stand]))[0]
    centre = grid.to_world(medoid[None, :])[0]
    space = _open_space(grid, medoid, unknown_labels, config.open_space_radius)
    return FrontierRegion(
        standpoint=(float(standpoint[0]), float(standpoint[1])),
        centre=(float(centre[0]), float(centre[1])),
        length=cells.shape[0] * grid.resolution,
        open_space=space,
    )


def _open_space(
    grid: OccupancyGrid, medoid: np.ndarray, unknown_labels: np.ndarray, radius: float
) -> float:
    """Area of unknown cells within `radius` connected (4-way) to this frontier's unknown cells."""
    r = int(np.ceil(radius / grid.resolution))
    i0, j0 = max(medoid[0] - r, 0), max(medoid[1] - r, 0)
    window = unknown_labels[i0 : medoid[0] + r + 1, j0 : medoid[1] + r + 1]
    ii, jj = np.ogrid[: window.shape[0], : window.shape[1]]
    disc = (ii + i0 - medoid[0]) ** 2 + (jj + j0 - medoid[1]) ** 2 <= r * r
    label = unknown_labels[tuple(medoid)]
    return float(((window == label) & disc).sum()) * grid.resolution**2
