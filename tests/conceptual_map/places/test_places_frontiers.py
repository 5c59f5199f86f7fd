"""Frontier regions: reachability agrees with the path planner, open space, standpoints."""

import numpy as np

from conceptual_map.metric import OccupancyGrid, distance_field
from conceptual_map.places import PlaceMapConfig, frontier_regions
from conceptual_map.places.frontiers import reachable_mask


def diagonal_wall_grid() -> OccupancyGrid:
    """1 x 1 m all free, split by a one-cell diagonal wall that is open only corner to corner."""
    grid = OccupancyGrid(origin=(0.0, 0.0), size=(1.0, 1.0))
    grid.logodds[:] = grid.model.clamp_min
    for i in range(grid.shape[0]):
        grid.logodds[i, i] = grid.model.clamp_max
    grid._touch()
    return grid


def test_reachable_cells_are_exactly_those_the_planner_reaches() -> None:
    grid = diagonal_wall_grid()
    reachable = reachable_mask(grid, (0.8, 0.2), radius=0.01)
    field = distance_field(grid, (0.8, 0.2), robot_radius=0.01)
    assert np.array_equal(reachable, np.isfinite(field))
    assert not reachable[grid.cell_of((0.2, 0.8))]  # only a corner-to-corner gap leads there


def test_placeholder_region_reports_unknown_space_behind_a_gap() -> None:
    grid = OccupancyGrid(origin=(0.0, 0.0), size=(4.0, 2.0))
    grid.logodds[:] = grid.model.clamp_max  # all walls ...
    grid.logodds[2:38, 2:38] = grid.model.clamp_min  # ... a free 1.8 m room
    grid.logodds[38:40, 15:25] = grid.model.clamp_min  # a 0.5 m gap in its east wall
    grid.logodds[40:78, 2:38] = 0  # an unknown 1.9 x 1.8 m room behind it
    grid._touch()
    regions = frontier_regions(grid, (1.0, 1.0), PlaceMapConfig(robot_radius=0.1))
    assert len(regions) == 1
    region = regions[0]
    assert abs(region.centre[0] - 2.025) < 1e-9 and 0.75 < region.centre[1] < 1.25
    assert abs(region.open_space - 38 * 36 * 0.05**2) < 1e-6  # all of the unknown room
    assert region.standpoint[0] < 2.0  # on the known side
