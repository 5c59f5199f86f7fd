"""Rooms seen but not entered: free space no place stands in becomes a goal (a placeholder)."""

from conceptual_map.metric import OccupancyGrid
from conceptual_map.places import PlaceMapConfig
from conceptual_map.places.unvisited import unvisited_regions

CONFIG = PlaceMapConfig(robot_radius=0.1)


def hall_and_room(door: bool = True) -> OccupancyGrid:
    """A 1 m wide hall (x 0..6) and a 2.8 x 3.8 m room north of it behind a 1 m opening, all of it
    mapped free (as if seen through the doorway); walls elsewhere."""
    grid = OccupancyGrid(origin=(0.0, 0.0), size=(6.0, 5.0))
    grid.logodds[:] = grid.model.clamp_max
    grid.logodds[2:118, 2:20] = grid.model.clamp_min  # hall: y 0.1..1.0
    grid.logodds[62:78, 20:22] = grid.model.clamp_min  # 0.8 m opening in its north wall
    grid.logodds[42:98, 22:98] = grid.model.clamp_min  # room: x 2.1..4.9, y 1.1..4.9
    grid._touch()
    return grid


def test_a_room_seen_through_its_door_gets_a_goal_inside() -> None:
    grid = hall_and_room()
    places = [(0.5, 0.5), (1.5, 0.5), (2.5, 0.5), (3.5, 0.5), (4.5, 0.5), (5.5, 0.5)]
    door = ((3.1, 1.05), (3.9, 1.05))
    regions = unvisited_regions(grid, (0.5, 0.5), places, [door], CONFIG)
    assert len(regions) == 1
    region = regions[0]
    assert 2.1 < region.standpoint[0] < 4.9 and 1.1 < region.standpoint[1] < 4.9
    assert 9.0 < region.open_space < 11.0  # about the room's 2.8 x 3.8 m
    assert region.length == 0.0  # no frontier: the space is mapped


def test_without_a_recognised_door_the_far_part_of_the_room_still_counts() -> None:
    grid = hall_and_room()
    places = [(0.5, 0.5), (1.5, 0.5), (2.5, 0.5), (3.5, 0.5), (4.5, 0.5), (5.5, 0.5)]
    regions = unvisited_regions(grid, (0.5, 0.5), places, [], CONFIG)
    assert len(regions) == 1 and regions[0].standpoint[1] > 3.5  # > visit_radius from places


def test_entering_the_room_or_a_frontier_there_removes_the_goal() -> None:
    grid = hall_and_room()
    hall = [(0.5, 0.5), (1.5, 0.5), (2.5, 0.5), (3.5, 0.5), (4.5, 0.5), (5.5, 0.5)]
    door = ((3.1, 1.05), (3.9, 1.05))
    inside = hall + [(3.5, 2.5)]
    assert unvisited_regions(grid, (0.5, 0.5), inside, [door], CONFIG) == []
    covered = unvisited_regions(grid, (0.5, 0.5), hall, [door], CONFIG, covered=[(3.5, 3.0)])
    assert covered == []


def test_unreachable_or_small_space_is_no_goal() -> None:
    grid = hall_and_room()
    grid.logodds[62:78, 20:22] = grid.model.clamp_max  # the opening closed: unreachable
    grid._touch()
    places = [(0.5, 0.5), (5.5, 0.5)]
    assert unvisited_regions(grid, (0.5, 0.5), places, [], CONFIG) == []
    small = PlaceMapConfig(robot_radius=0.1, min_unvisited_area=20.0)
    assert unvisited_regions(hall_and_room(), (0.5, 0.5), places, [], small) == []
