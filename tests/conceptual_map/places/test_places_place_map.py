"""The place map on a synthetic corridor with two rooms, driven along a scripted path."""

from dataclasses import dataclass

import networkx as nx
import numpy as np
import pytest

from conceptual_map.errors import MapError
from conceptual_map.metric import CellState, OccupancyGrid
from conceptual_map.metric.synthetic import BoxWorld, rooms_world
from conceptual_map.places import Change, EntityKind, MapEvent, PlaceMap

CORRIDOR, ROOM_K, ROOM_O = (0.0, 2.5, 8.0, 4.0), (0.0, 4.0, 4.0, 7.0), (4.0, 4.0, 8.0, 7.0)
DOORS = [(2.0, 4.0, 0.9), (6.0, 4.0, 0.9)]
ROUTE = [(1, 3.25), (7, 3.25), (6, 3.25), (6, 5.5), (7, 6), (5, 6), (6, 5), (6, 3.25),
         (2, 3.25), (2, 5.5), (1, 6), (3, 6), (2, 5), (2, 3.25)]  # fmt: skip


def poses_along(route: list, step: float = 0.5) -> list[tuple[float, float, float]]:
    out = [(*route[0], 0.0)]
    for a, b in zip(route, route[1:], strict=False):
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        yaw = float(np.arctan2(b[1] - a[1], b[0] - a[0]))
        out += [(*(a + (b - a) * t), yaw) for t in np.linspace(0, 1, n + 1)[1:]]
    return out


@dataclass
class Run:
    world: BoxWorld
    grid: OccupancyGrid
    place_map: PlaceMap
    events: list[list[MapEvent]]


def explore(world: BoxWorld, route: list) -> Run:
    grid, place_map, events = OccupancyGrid(), PlaceMap(), []
    for k, pose in enumerate(poses_along(route)):
        grid.integrate_scan(world.laser(pose, beams=480, fov=4.18))
        events.append(place_map.update(grid, pose, time=float(k)))
    return Run(world, grid, place_map, events)


@pytest.fixture(scope="module")
def run() -> Run:
    return explore(rooms_world([CORRIDOR, ROOM_K, ROOM_O], DOORS), ROUTE)


def rect_of(point: tuple[float, float], margin: float = 0.15) -> int | None:
    for k, (x0, y0, x1, y1) in enumerate([CORRIDOR, ROOM_K, ROOM_O]):
        if x0 + margin < point[0] < x1 - margin and y0 + margin < point[1] < y1 - margin:
            return k
    return None


def test_doors_are_found_at_both_narrow_openings_and_confirmed(run: Run) -> None:
    doors = sorted(run.place_map.doors.values(), key=lambda d: d.centre)
    assert len(doors) == 2
    for door, (x, y, width) in zip(doors, DOORS, strict=True):
        assert np.hypot(door.centre[0] - x, door.centre[1] - y) < 0.15
        assert width - 0.15 <= door.width <= width + 0.05
        assert door.confirmed


def test_rooms_are_the_place_groups_separated_by_doors(run: Run) -> None:
    rooms = list(run.place_map.rooms.values())
    assert len(rooms) == 3
    seen = set()
    for room in rooms:
        rects = {rect_of(run.place_map.places[p].position) for p in room.places} - {None}
        assert len(rects) == 1, room  # every place of a room lies in one world room
        seen |= rects
    assert seen == {0, 1, 2}
    corridor = next(r for r in rooms if rect_of(run.place_map.places[min(r.places)].position) == 0)
    assert corridor.doors == frozenset(run.place_map.doors)


def test_room_geometry_tells_a_corridor_from_a_room(run: Run) -> None:
    by_rect = {
        rect_of(run.place_map.places[sorted(r.places)[0]].position): r
        for r in run.place_map.rooms.values()
    }
    corridor, kitchen = by_rect[0], by_rect[1]
    inner = (4.0 - 0.12) * (3.0 - 0.12)
    assert corridor.elongation > 4.0 and kitchen.elongation < 1.6
    assert inner * 0.85 < kitchen.area < inner * 1.05


def test_places_are_spaced_and_connected(run: Run) -> None:
    positions = np.array([p.position for p in run.place_map.places.values()])
    gaps = np.linalg.norm(positions[:, None] - positions[None], axis=2)
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() >= 0.5 and len(positions) >= 12
    places_only = run.place_map.graph.subgraph(run.place_map.places)
    assert nx.is_connected(places_only)


def test_placeholders_sit_at_reachable_frontiers(run: Run) -> None:
    first = [e for e in run.events[0] if e.kind is EntityKind.PLACEHOLDER]
    assert len(first) >= 3  # the corridor's far end and both door openings
    grid = OccupancyGrid()
    grid.integrate_scan(run.world.laser((1.0, 3.25, 0.0), beams=480, fov=4.18))
    frontier = grid.to_world(np.argwhere(grid.frontier_mask()))
    for event in first:
        ph = event.entity
        assert np.min(np.linalg.norm(frontier - ph.frontier_centre, axis=1)) < 1e-6
        assert grid.state_grid()[grid.cell_of(ph.position)] == CellState.FREE
        assert ph.open_space >= 0.5 and ph.place == "place1"


def test_every_placeholder_vanishes_once_everything_is_explored(run: Run) -> None:
    assert run.place_map.placeholders == {}
    changes: dict[str, list[Change]] = {}
    for batch in run.events:
        for e in batch:
            if e.kind is EntityKind.PLACEHOLDER:
                changes.setdefault(e.id, []).append(e.change)
    assert len(changes) >= 3
    for history in changes.values():
        assert history[0] is Change.APPEARED and history[-1] is Change.VANISHED


def test_a_narrow_corridor_is_not_a_door() -> None:
    world = BoxWorld()
    for box in _walls_with_passage(length=2.0):
        world.add_box(*box)
    result = explore(world, [(1.5, 1.5), (7.5, 1.5)])
    assert result.place_map.doors == {}
    assert len(result.place_map.rooms) == 1


def test_a_short_opening_of_the_same_width_is_a_door() -> None:
    world = BoxWorld()
    for box in _walls_with_passage(length=0.2):
        world.add_box(*box)
    result = explore(world, [(1.5, 1.5), (7.5, 1.5)])
    assert len(result.place_map.doors) == 1  # a thick wall with one opening
    assert len(result.place_map.rooms) == 2


def _walls_with_passage(length: float) -> list[tuple[float, float, float, float]]:
    """Two 3 x 3 m rooms joined by a 1.0 m wide passage of the given length."""
    t, w, e = 0.06, 3.5, 3.5 + length
    return [
        (-t, -t, 9 + t, t), (-t, 3 - t, 9 + t, 3 + t),  # south, north
        (-t, -t, t, 3 + t), (9 - t, -t, 9 + t, 3 + t),  # west, east
        (w - t, t, w + t, 1.0), (w - t, 2.0, w + t, 3 - t),  # passage mouth, west
        (e - t, t, e + t, 1.0), (e - t, 2.0, e + t, 3 - t),  # passage mouth, east
        (w, 1.0 - t, e, 1.0 + t), (w, 2.0 - t, e, 2.0 + t),  # passage sides
    ]  # fmt: skip


def test_bad_poses_and_settings_are_errors_naming_them() -> None:
    from conceptual_map.errors import MapError
    from conceptual_map.places import PlaceMapConfig

    with pytest.raises(MapError, match="pose 1 must start with finite x, y"):
        PlaceMap().follow(OccupancyGrid(), [(0.0, 0.0, 0.0), (float("nan"), 1.0, 0.0)])
    with pytest.raises(MapError, match="place_spacing must be positive"):
        PlaceMapConfig(place_spacing=0.0)
    assert PlaceMap().follow(OccupancyGrid(), []) == []


def test_room_split_by_a_new_door_is_reported(run: Run) -> None:
    rooms = [e for batch in run.events for e in batch if e.kind is EntityKind.ROOM]
    appeared = [e for e in rooms if e.change is Change.APPEARED]
    assert len(appeared) == 3  # the corridor first, then one room behind each door
    door_times = sorted(
        e.time for b in run.events for e in b if e.kind is EntityKind.DOOR and e.entity.confirmed
    )
    assert all(any(abs(a.time - t) <= 1.0 for t in door_times) for a in appeared[1:])


def test_room_links_join_the_corridor_to_each_room_through_its_door(run: Run) -> None:
    links = run.place_map.room_links()
    assert len(links) == 2
    rect = {
        r.id: rect_of(run.place_map.places[sorted(r.places)[0]].position)
        for r in run.place_map.rooms.values()
    }
    joined = sorted(tuple(sorted((rect[a], rect[b]))) for a, b in links.values())
    assert joined == [(0, 1), (0, 2)]


def test_an_exported_map_is_restored_and_goes_on_from_a_new_pose(run: Run) -> None:
    """What a later task keeps (`export`) gives the same places, doors and rooms back, the
    conceptual map's events for every room, and the robot at no place until it moves: a
    new pose does not continue the old path with a straight leg through the walls."""
    import json

    data = json.loads(json.dumps(run.place_map.export()))  # plain data, as it is stored
    assert "placeholders" not in data  # derived from the grid again
    restored, events = PlaceMap.restored(data)
    old = run.place_map
    assert restored.places == old.places and restored.doors == old.doors
    assert restored.rooms == old.rooms
    assert {e.id for e in events} == set(old.rooms)
    assert all(e.kind is EntityKind.ROOM and e.change is Change.APPEARED for e in events)
    assert restored.current_place is None
    grid = OccupancyGrid.restored(run.grid.origin, run.grid.logodds, run.grid.resolution)
    assert np.array_equal(grid.state_grid(), run.grid.state_grid())
    start = next(iter(old.places.values())).position
    restored.update(grid, (*start, 0.0), time=1000.0)
    assert set(restored.places) == set(old.places)  # it stands at a place it knew
    assert set(restored.rooms) == set(old.rooms) and restored.doors == old.doors
    assert restored.current_place is not None
    with pytest.raises(MapError, match="nowhere"):
        PlaceMap.restored({**data, "edges": [["place1", "nowhere", True, None]]})
    with pytest.raises(MapError, match="malformed"):
        PlaceMap.restored({**data, "places": {"place1": [1.0]}})
    with pytest.raises(ValueError, match="int8"):
        OccupancyGrid.restored((0.0, 0.0), np.zeros((3, 3)), 0.05)
