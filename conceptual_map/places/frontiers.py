"""Reachable frontier regions of the 2D grid: where placeholders go (§2, §3 of the active visual
search paper by Göbelbecker et al.).

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
STANDPOINT_MARGIN = 0.1  # prefer standpoints this far beyond the robot radius from obstacles


@dataclass(frozen=True)
class FrontierRegion:
    """One frontier region: a standing point in reachable space and what lies behind."""

    standpoint: tuple[float, float]
    centre: tuple[float, float]
    length: float  # metres of frontier (cell count x resolution)
    open_space: float  # m^2 of connected unknown within the configured radius


def reachable_mask(grid: OccupancyGrid, robot: tuple[float, float], radius: float) -> np.ndarray:
    """Traversable cells connected to the robot (or to the traversable cell nearest to it).

    4-connected: exactly the cells A* (8 moves, no corner cutting) can reach.
    """
    traversable = grid.traversable(radius)
    if not traversable.any():
        return traversable
    labels, _ = ndimage.label(traversable)
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
    reachable = reachable_mask(grid, robot, config.reach_radius)
    if not reachable.any():
        return []
    reach = int(np.ceil(config.reach_tolerance / grid.resolution)) + 1
    window = _bounding_window(reachable, reach, grid.shape)
    far = ndimage.distance_transform_edt(~reachable[window]) * grid.resolution
    frontier = grid.frontier_mask()[window] & (far <= config.reach_tolerance)
    labels, _ = ndimage.label(frontier, structure=_EIGHT)
    sizes = np.bincount(labels.ravel())
    unknown_labels, _ = ndimage.label(grid.state_grid() == CellState.UNKNOWN)
    stand_masks = standpoint_masks(grid, reachable, config.robot_radius)
    offset = np.array([window[0].start, window[1].start])
    regions = []
    for k, box in enumerate(ndimage.find_objects(labels), start=1):
        if sizes[k] * grid.resolution < config.min_frontier_length:
            continue
        cells = np.argwhere(labels[box] == k) + [box[0].start, box[1].start] + offset
        region = _describe(grid, cells, stand_masks, unknown_labels, config)
        if region is not None and region.open_space >= config.min_open_space:
            regions.append(region)
    return regions


def standpoint_masks(grid: OccupancyGrid, reachable: np.ndarray, radius: float
                     ) -> tuple[np.ndarray, ...]:
    """Where to stand near a goal, in order of preference: roomy (`radius` plus a margin from
    obstacles), clear of obstacles by `radius`, then anywhere `reachable` (which may have been
    reached only by squeezing through a gap narrower than `2 * radius`)."""
    clearance = grid.clearance()
    return (reachable & (clearance >= radius + STANDPOINT_MARGIN),
            reachable & (clearance >= radius), reachable)


def _bounding_window(mask: np.ndarray, margin: int, shape: tuple[int, ...]) -> tuple[slice, ...]:
    """The bounding box of a mask's True cells, grown by `margin` cells."""
    rows, cols = np.nonzero(mask.any(axis=1))[0], np.nonzero(mask.any(axis=0))[0]
    return (
        slice(max(rows[0] - margin, 0), min(rows[-1] + margin + 1, shape[0])),
        slice(max(cols[0] - margin, 0), min(cols[-1] + margin + 1, shape[1])),
    )


def _describe(
    grid: OccupancyGrid,
    cells: np.ndarray,
    stand_masks: tuple[np.ndarray, ...],
    unknown_labels: np.ndarray,
    config: PlaceMapConfig,
) -> FrontierRegion | None:
    """Where to stand (the first mask, in order of preference, with a cell near the frontier's
    medoid), the frontier's centre and length, and the open space behind it."""
    medoid = cells[np.argmin(np.linalg.norm(cells - cells.mean(axis=0), axis=1))]
    window = int(np.ceil(2 * config.reach_tolerance / grid.resolution))
    stand = None
    for mask in stand_masks:
        stand = nearest_true(mask, medoid, window)
        if stand is not None:
            break
    if stand is None:
        return None
    standpoint = grid.to_world(np.asarray([stand]))[0]
    centre = grid.to_world(medoid[None, :])[0]
    space = _open_space(grid, medoid, unknown_labels, config.open_space_radius)
    return FrontierRegion(
        standpoint=(float(standpoint[0]), float(standpoint[1])),
        centre=(float(centre[0]), float(centre[1])),
        length=cells.shape[0] * grid.resolution,
        open_space=space,
    )


def nearest_true(mask: np.ndarray, cell: np.ndarray, radius: int) -> np.ndarray | None:
    """The True cell of `mask` nearest to `cell` within a square window of `radius` cells."""
    i0, j0 = max(cell[0] - radius, 0), max(cell[1] - radius, 0)
    found = np.argwhere(mask[i0 : cell[0] + radius + 1, j0 : cell[1] + radius + 1])
    if found.shape[0] == 0:
        return None
    found += [i0, j0]
    return found[np.argmin(np.linalg.norm(found - cell, axis=1))]


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
