"""Rooms as floor: `PlaceMap.room_extents` (the free cells each room holds) and
`PlaceMap.room_at` (the room a seen object stands in), on the synthetic corridor with two
rooms of the place-map tests."""

from __future__ import annotations

import numpy as np
import pytest

from conceptual_map.metric.synthetic import rooms_world

from .test_places_place_map import CORRIDOR, DOORS, ROOM_K, ROOM_O, ROUTE, Run, explore


@pytest.fixture(scope="module")
def run() -> Run:
    return explore(rooms_world([CORRIDOR, ROOM_K, ROOM_O], DOORS), ROUTE)


@pytest.fixture(scope="module")
def peeked() -> Run:
    """Along the corridor only, past both doorways: the rooms are seen, never entered."""
    return explore(rooms_world([CORRIDOR, ROOM_K, ROOM_O], DOORS), [(1, 3.25), (7, 3.25)])


def room_of_rect(run: Run, rect: tuple[float, float, float, float]) -> str:
    x0, y0, x1, y1 = rect
    return next(r.id for r in run.place_map.rooms.values()
                if any(x0 < run.place_map.places[p].position[0] < x1
                       and y0 < run.place_map.places[p].position[1] < y1 for p in r.places))


def test_each_room_holds_the_free_floor_of_its_own_world_room(run: Run) -> None:
    owner, ids = run.place_map.room_extents(run.grid)
    assert sorted(ids) == sorted(run.place_map.rooms)
    for rect in (CORRIDOR, ROOM_K, ROOM_O):
        x0, y0, x1, y1 = rect
        rid = room_of_rect(run, rect)
        cells = np.argwhere(owner > 0)
        centres = run.grid.to_world(cells)
        inside = ((centres[:, 0] > x0 + 0.1) & (centres[:, 0] < x1 - 0.1)
                  & (centres[:, 1] > y0 + 0.1) & (centres[:, 1] < y1 - 0.1))
        named = np.asarray(ids)[owner[cells[:, 0], cells[:, 1]] - 1]
        assert inside.sum() > 0
        assert np.mean(named[inside] == rid) > 0.98  # its floor is its own
        assert np.mean(inside[named == rid]) > 0.95  # and it holds little else
        assert run.place_map.rooms[rid].area == pytest.approx(
            np.count_nonzero(named == rid) * run.grid.resolution ** 2, rel=0.05)


def test_an_object_is_in_the_room_whose_floor_surrounds_it(run: Run) -> None:
    pm, grid = run.place_map, run.grid
    kitchen, corridor = room_of_rect(run, ROOM_K), room_of_rect(run, CORRIDOR)
    assert pm.room_at(grid, (2.0, 6.9)) == kitchen  # against the kitchen's far wall
    assert pm.room_at(grid, (2.0, 4.3)) == kitchen  # just inside the kitchen door
    assert pm.room_at(grid, (2.0, 3.7)) == corridor  # just outside it
    assert pm.room_at(grid, (0.1, 3.25)) == corridor  # in the corridor's end wall


def test_an_object_seen_through_a_doorway_is_in_no_room_yet(peeked: Run) -> None:
    """The rooms' floor was seen from the corridor; the place map has one room (the
    corridor). An object in a room behind a door is not in the corridor; one in the corridor
    is."""
    pm, grid = peeked.place_map, peeked.grid
    assert len(pm.rooms) == 1
    (corridor,) = pm.rooms
    assert len(pm.doors) == 2  # the doors were passed (not through)
    assert pm.room_at(grid, (2.0, 5.0)) is None
    assert pm.room_at(grid, (6.0, 5.5)) is None
    assert pm.room_at(grid, (4.0, 2.6)) == corridor
    # far from any seen floor: the room of the nearest place, as before extents
    assert pm.room_at(grid, (30.0, 30.0)) == corridor
