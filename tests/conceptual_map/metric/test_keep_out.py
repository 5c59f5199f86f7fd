"""Keep-out discs: cells the robot's centre must avoid whatever the scans say."""

import numpy as np
import pytest

from conceptual_map.metric import OccupancyGrid, plan_path
from conceptual_map.metric.logodds import CellState


def _free_grid() -> OccupancyGrid:
    grid = OccupancyGrid(origin=(0.0, 0.0), size=(4.0, 2.0))
    grid.logodds[:] = -20  # every cell believed free
    assert (grid.state_grid() == CellState.FREE).all()
    return grid


def test_a_keep_out_disc_is_not_traversable_and_paths_go_around() -> None:
    grid = _free_grid()
    straight = plan_path(grid, (0.5, 1.0), (3.5, 1.0), 0.2)
    assert straight.length == pytest.approx(3.0, abs=0.05)
    version = grid.version
    grid.set_keep_out([(2.0, 1.0, 0.3)])
    assert grid.version > version
    assert not grid.traversable(0.2)[grid.cell_of((2.0, 1.0))]
    around = plan_path(grid, (0.5, 1.0), (3.5, 1.0), 0.2)
    assert around.found and around.length > straight.length
    points = np.asarray(around.waypoints)
    assert (np.hypot(points[:, 0] - 2.0, points[:, 1] - 1.0) > 0.3 - 0.05).all()
    grid.set_keep_out([])
    assert grid.traversable(0.2)[grid.cell_of((2.0, 1.0))]
