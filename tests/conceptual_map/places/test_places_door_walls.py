"""Doors part rooms only between walls (`doors.between_walls`): a door hypothesis along the
edge of a piece of furniture (its inside unseen) stays a hypothesis and splits no room.

Measured on generated dev worlds, such hypotheses (gaps between chairs, between a table's
corner and a wall) split rooms on almost every floor; the jambs of the real doors were thin
walls with free floor on both faces."""

from __future__ import annotations

import numpy as np
import pytest

from conceptual_map.metric.synthetic import rooms_world
from conceptual_map.places.doors import Opening, between_walls

from .test_places_place_map import CORRIDOR, DOORS, ROOM_K, ROOM_O, Run, explore, rect_of

# in the office (ROOM_O: 4..8 x 4..7), against its west wall: the only way from the office's
# south half to its north half is the 1.44 m gap between the table's end and the east wall
TABLE = (4.06, 5.0, 6.5, 5.8)
# round the office, through that gap and back
ROUTE = [(1, 3.25), (7, 3.25), (6, 3.25), (6, 4.5), (4.5, 4.5), (7.3, 4.5), (7.3, 6.5),
         (4.5, 6.5), (7.3, 6.5), (7.3, 4.5), (6, 4.5), (6, 3.25), (2, 3.25), (2, 5.5), (1, 6),
         (3, 6), (2, 3.25)]
# the chord from the table's north-east corner along its edge to the east wall's face
PHANTOM = ((6.5, 5.8), (7.94, 5.8))


@pytest.fixture(scope="module")
def run() -> Run:
    world = rooms_world([CORRIDOR, ROOM_K, ROOM_O], DOORS)
    world.add_box(*TABLE[:2], *TABLE[2:], 0.0, 0.75)
    return explore(world, ROUTE)


def test_real_doors_are_between_walls(run: Run) -> None:
    assert len(run.place_map.doors) == 2
    for door in run.place_map.doors.values():
        assert between_walls(run.grid, door.ends, run.place_map.config.door_max_depth)


def test_a_chord_along_a_table_edge_is_not_between_walls(run: Run) -> None:
    assert not between_walls(run.grid, PHANTOM, run.place_map.config.door_max_depth)
    assert not between_walls(run.grid, PHANTOM[::-1], run.place_map.config.door_max_depth)


def test_a_door_passed_by_is_judged_from_the_side_the_robot_was_on() -> None:
    """Along the corridor only: a wall's face on the room side, next to the jambs, is mostly
    hidden from the corridor, so only the corridor's side is asked. Seen from there the
    jambs are walls, and the door parts the corridor from the room seen through it."""
    peek = explore(rooms_world([CORRIDOR, ROOM_K, ROOM_O], DOORS), [(1, 3.25), (7, 3.25)])
    pm = peek.place_map
    assert len(pm.doors) == 2
    for door in pm.doors.values():
        (a, b), depth = door.ends, pm.config.door_max_depth
        d = np.subtract(b, a)
        corridor_side = 1 if float(np.dot([-d[1], d[0]], [0.0, -1.0])) > 0 else -1
        assert between_walls(peek.grid, door.ends, depth, sides=(corridor_side,))
    assert len(pm.rooms) == 1
    (corridor,) = pm.rooms
    assert pm.room_at(peek.grid, (2.0, 5.0)) is None  # the kitchen seen through its door


def test_a_door_hypothesis_along_furniture_splits_no_room(run: Run) -> None:
    pm, grid = run.place_map, run.grid
    a, b = np.asarray(PHANTOM[0]), np.asarray(PHANTOM[1])
    opening = Opening(0.5 * (a + b), float(np.linalg.norm(b - a)), 0.0)
    # as the detector reports it (the path went across its line on both sides)
    pm._add_openings([opening], np.array([[7.3, 5.3], [7.3, 6.3]]), time=1e3)
    pm.refresh(grid)
    assert len(pm.doors) == 3  # still a door hypothesis (the executor keeps clear of it)
    offices = [r for r in pm.rooms.values()
               if any(rect_of(pm.places[p].position) == 2 for p in r.places)]
    assert len(offices) == 1  # the office is one room
    (office,) = offices
    assert {rect_of(pm.places[p].position) for p in office.places} <= {2, None}
    owner, ids = pm.room_extents(grid)
    k = ids.index(office.id) + 1
    for point in ((5.0, 6.4), (7.3, 6.0), (7.3, 5.0), (4.5, 4.5)):  # both sides of its line
        cell = grid.to_cell(np.asarray([point]))[0]
        assert owner[cell[0], cell[1]] == k


@pytest.mark.parametrize("side_room, doors", [
    ((3.0, 4.0, 5.0, 6.0), [(4.0, 4.0, 0.9)]),  # small: all of it seen through the door
    ((2.0, 4.0, 6.0, 7.0), [(3.0, 4.0, 0.9), (5.0, 4.0, 0.9)]),  # two doors off the corridor
])
def test_a_room_seen_through_its_doors_from_the_corridor_is_not_the_corridors(
        side_room, doors) -> None:
    """Driving along the corridor past the doors only: every door is a hypothesis parting
    the rooms (found where the mapped floor narrows, not only on the path or on the way to
    a frontier), so the floor seen through a door is not the corridor's."""
    corridor = (0.0, 2.5, 8.0, 4.0)
    peek = explore(rooms_world([corridor, side_room], doors), [(1, 3.25), (7, 3.25)])
    pm = peek.place_map
    centres = sorted(tuple(round(v) for v in d.centre) for d in pm.doors.values())
    assert centres == [(round(x), round(y)) for x, y, _ in doors]
    assert set(pm._walled) == set(pm.doors)
    (corridor_room,) = pm.rooms
    x0, y0, x1, y1 = side_room
    assert pm.room_at(peek.grid, (0.5 * (x0 + x1), 0.5 * (y0 + y1) + 0.5)) is None
    assert pm.room_at(peek.grid, (4.0, 3.25)) == corridor_room
