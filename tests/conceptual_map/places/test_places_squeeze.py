"""Free space behind a gap the grid shows narrower than the robot's planning disc, but wide
enough to squeeze through, still gets a placeholder (the width is uncertain until tried)."""

import pytest

from conceptual_map.errors import MapError
from conceptual_map.metric import OccupancyGrid
from conceptual_map.metric.synthetic import rooms_world
from conceptual_map.places import PlaceMap, PlaceMapConfig

POSES = [(1.5, 2.0, 0.0), (2.3, 3.4, 0.0)]


def _beyond(gap: float, squeeze: float | None) -> list:
    """Placeholders beyond a 0.4 m thick wall-to-box barrier at x 3.0-3.4 with a `gap` (m)
    between the box and the room's far wall, mapped from the near side only."""
    world = rooms_world([(0.0, 0.0, 7.0, 4.0)], [], wall=0.1)
    world.add_box(3.0, 0.0, 3.4, 3.95 - gap)
    grid = OccupancyGrid()
    place_map = PlaceMap(PlaceMapConfig(robot_radius=0.36, squeeze_radius=squeeze))
    for pose in POSES:
        grid.integrate_scan(world.laser(pose, beams=1440, max_range=8.0))
        place_map.update(grid, pose)
    return [p for p in place_map.placeholders.values() if p.position[0] > 3.5]


def test_a_gap_the_grid_under_measures_still_leads_to_a_placeholder() -> None:
    # 0.74 m: a 0.68 m robot passes, the grid's clearance (a lower bound) shows it below the
    # 0.72 m planning disc; squeezing with 0.29 m it is reachable
    assert not _beyond(0.74, None)
    found = _beyond(0.74, 0.29)
    assert found and all(p.open_space > 1.0 for p in found)


def test_a_gap_narrower_than_the_squeeze_gets_no_placeholder() -> None:
    assert not _beyond(0.6, 0.29)


def test_the_squeeze_radius_may_not_exceed_the_planning_radius() -> None:
    assert PlaceMapConfig(robot_radius=0.3).reach_radius == 0.3
    assert PlaceMapConfig(robot_radius=0.3, squeeze_radius=0.25).reach_radius == 0.25
    with pytest.raises(MapError, match="squeeze_radius"):
        PlaceMapConfig(robot_radius=0.3, squeeze_radius=0.35)
    with pytest.raises(MapError, match="squeeze_radius"):
        PlaceMapConfig(robot_radius=0.3, squeeze_radius=-0.1)
