"""Reachable free space that no place stands in: rooms seen (through a doorway, or from far
off) but not entered. Mapping them leaves no frontier, so without these the planner would have
nothing to go to there (the planner of the active visual search paper by Göbelbecker et al.
plans only over places and placeholders).

A region is unvisited when it lies beyond a mapped door from every place, or farther than
`visit_radius` from all places (a door not yet recognised, or the far end of a large room).
Each such region of at least `min_unvisited_area` becomes a placeholder-like goal: a standpoint
near its middle, its free area as the open space behind it.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.places.config import PlaceMapConfig
from conceptual_map.places.frontiers import (
    STANDPOINT_MARGIN,
    FrontierRegion,
    nearest_true,
    reachable_mask,
)
from conceptual_map.places.rooms import Chord, free_regions


def unvisited_regions(
    grid: OccupancyGrid,
    robot: tuple[float, float],
    places: list[tuple[float, float]],
    doors: list[Chord],
    config: PlaceMapConfig,
    covered: list[tuple[float, float]] = (),
) -> list[FrontierRegion]:
    """Unvisited reachable regions, without those holding a point of `covered` (e.g. the
    standpoint of a frontier placeholder already leading there)."""
    if not places:
        return []
    reachable = reachable_mask(grid, robot, config.reach_radius)
    if not reachable.any():
        return []
    labels = free_regions(grid, doors)
    cells = grid.to_cell(np.asarray(places, dtype=float))
    cells = cells[grid.inside(cells)]
    visited = np.isin(labels, np.unique(labels[cells[:, 0], cells[:, 1]]))
    seeds = np.ones(grid.shape, dtype=bool)
    seeds[cells[:, 0], cells[:, 1]] = False
    far = ndimage.distance_transform_edt(seeds) * grid.resolution > config.visit_radius
    parts, count = ndimage.label(reachable & (~visited | far))
    if count == 0:
        return []
    skip = _labels_at(grid, parts, covered)
    min_cells = config.min_unvisited_area / grid.resolution**2
    sizes = np.bincount(parts.ravel(), minlength=count + 1)
    clearance = grid.clearance()
    prefer = (clearance >= config.robot_radius + STANDPOINT_MARGIN,
              clearance >= config.robot_radius)
    regions = []
    for k, box in enumerate(ndimage.find_objects(parts), start=1):
        if sizes[k] < min_cells or k in skip:
            continue
        region = _describe(grid, parts[box] == k, (box[0].start, box[1].start), prefer)
        regions.append(region)
    return regions


def _labels_at(grid: OccupancyGrid, parts: np.ndarray, points: list[tuple[float, float]]
               ) -> set[int]:
    if not len(points):
        return set()
    cells = grid.to_cell(np.asarray(points, dtype=float))
    cells = cells[grid.inside(cells)]
    return {int(v) for v in parts[cells[:, 0], cells[:, 1]]} - {0}


def _describe(grid: OccupancyGrid, mask: np.ndarray, offset: tuple[int, int],
              prefer: tuple[np.ndarray, ...]) -> FrontierRegion:
    """A standpoint nearest the region's medoid (in the first of the `prefer` masks that has
    one in the region: roomy, then clear by the robot radius); its area as open space."""
    cells = np.argwhere(mask) + offset
    medoid = cells[np.argmin(np.linalg.norm(cells - cells.mean(axis=0), axis=1))]
    inside = np.zeros(grid.shape, dtype=bool)
    inside[cells[:, 0], cells[:, 1]] = True
    window = max(mask.shape)
    stand = None
    for mask_ in prefer:
        stand = nearest_true(inside & mask_, medoid, window)
        if stand is not None:
            break
    if stand is None:
        stand = medoid
    standpoint = grid.to_world(np.asarray([stand]))[0]
    centre = grid.to_world(medoid[None, :])[0]
    return FrontierRegion(
        standpoint=(float(standpoint[0]), float(standpoint[1])),
        centre=(float(centre[0]), float(centre[1])),
        length=0.0,
        open_space=float(cells.shape[0]) * grid.resolution**2,
    )
