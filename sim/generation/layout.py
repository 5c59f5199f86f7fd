"""Rooms and doors of a generated building: a spine (corridor or hall) with a row of rooms on
each side, doors on shared walls, some rooms entered only through a neighbour, some doors closed.

A door is closed only if every room stays reachable through open doors from every other room
(so from the robot's start, wherever it is).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from sim.generation.table import PlacementTable, StyleRule

GRID = 0.05  # every coordinate is a multiple of this (tidy YAML, exact shared walls)
DOOR_WIDTH = (0.8, 1.2)  # passable by both robots (pr2 footprint diameter 0.68 m)
DOOR_END_MARGIN = 0.3  # metres between a door edge and the end of its wall
_SECOND_DOOR_MIN_WIDTH = 3.6  # a room this wide may get a second door to the spine

Rect = tuple[float, float, float, float]


@dataclass(frozen=True)
class RoomPlan:
    """A room of the plan; `row` is -1 (south of the spine), 0 (the spine) or 1 (north)."""

    name: str
    category: str
    rect: Rect
    row: int


@dataclass(frozen=True)
class DoorPlan:
    """A door centred at `at` on the wall shared by `rooms`; `axis` 'x' is a wall x = const."""

    rooms: tuple[str, str]
    at: tuple[float, float]
    width: float
    axis: str
    open: bool = True


@dataclass(frozen=True)
class Layout:
    """The floor plan without furniture: world size, rooms (spine first) and doors."""

    size: tuple[float, float]
    rooms: tuple[RoomPlan, ...]
    doors: tuple[DoorPlan, ...]


def snap(value: float) -> float:
    """Round to the generator's grid (and to 2 decimals, so YAML stays short)."""
    return round(round(value / GRID) * GRID, 2)


def plan_layout(rng: np.random.Generator, table: PlacementTable, style: StyleRule,
                count: int) -> Layout:
    """Rooms of varied size off a spine, then doors, then closed doors."""
    categories = _categories(rng, style, count)
    n_north = count - count // 2 if rng.random() < 0.5 else count // 2
    depth_s, depth_n = (snap(rng.uniform(*style.row_depth)) for _ in range(2))
    spine_w = snap(rng.uniform(*style.spine_width))
    widths = [snap(rng.uniform(*table.rooms[c].width)) for c in categories]
    rows = {1: list(zip(categories[:n_north], widths[:n_north], strict=True)),
            -1: list(zip(categories[n_north:], widths[n_north:], strict=True))}
    length = snap(max(sum(w for _, w in row) for row in rows.values()))
    north, top = snap(depth_s + spine_w), snap(depth_s + spine_w + depth_n)
    spine = RoomPlan(style.spine, "corridor", (0.0, depth_s, length, north), 0)
    rooms = [spine]
    counters: dict[str, int] = {}
    rooms += _row_rooms(rows[1], 1, (north, top), length, counters)
    rooms += _row_rooms(rows[-1], -1, (0.0, depth_s), length, counters)
    size = (length, top)
    doors = _doors(rng, rooms, style)
    return Layout(size, tuple(rooms), tuple(_close_doors(rng, rooms, doors, style)))


def _categories(rng: np.random.Generator, style: StyleRule, count: int) -> list[str]:
    """The style's required categories (as many as fit), the rest drawn by weight (up to each
    category's cap), shuffled."""
    chosen = list(style.required[:count])
    while len(chosen) < count:
        names = [c for c in style.categories
                 if chosen.count(c) < style.at_most.get(c, count)]
        weights = np.array([style.categories[c] for c in names])
        chosen.append(str(rng.choice(names, p=weights / weights.sum())))
    return [chosen[i] for i in rng.permutation(len(chosen))]


def _row_rooms(entries: list[tuple[str, float]], row: int, span: tuple[float, float],
               length: float, counters: dict[str, int]) -> list[RoomPlan]:
    """Rooms side by side along the spine; a short row is stretched (at most 1.5x) toward it.

    Rooms are named category + number (`office1`, `office2`), counted over the whole building.
    """
    total = sum(w for _, w in entries)
    scale = min(length / total, 1.5) if total else 1.0
    rooms, x = [], 0.0
    for i, (category, width) in enumerate(entries):
        x1 = length if i == len(entries) - 1 and scale * total >= length - 1e-9 else snap(
            x + width * scale)
        counters[category] = counters.get(category, 0) + 1
        name = f"{category}{counters[category]}"
        rooms.append(RoomPlan(name, category, (x, span[0], x1, span[1]), row))
        x = x1
    return rooms


def _doors(rng: np.random.Generator, rooms: list[RoomPlan], style: StyleRule) -> list[DoorPlan]:
    """One door per room (to the spine, or to a neighbour for inner rooms), then extra doors."""
    spine = rooms[0]
    hosts = _inner_rooms(rng, rooms, style)
    doors: list[DoorPlan] = []
    for room in rooms[1:]:
        host = hosts.get(room.name)
        if host is None:
            two = (room.rect[2] - room.rect[0] >= _SECOND_DOOR_MIN_WIDTH
                   and rng.random() < style.extra_door_share)
            doors += _spine_doors(rng, spine, room, two)
        else:
            doors.append(_side_door(rng, room, host))
    linked = {frozenset(d.rooms) for d in doors}
    pairs = [(a, b) for a, b in _neighbours(rooms) if frozenset((a.name, b.name)) not in linked]
    doors += [_side_door(rng, a, b) for a, b in pairs if rng.random() < style.extra_door_share]
    if len(doors) < len(rooms):  # a tree: add one door, so that one can be closed
        doors += _extra_door(rng, rooms, pairs, doors)
    return doors


def _extra_door(rng: np.random.Generator, rooms: list[RoomPlan],
                pairs: list[tuple[RoomPlan, RoomPlan]], doors: list[DoorPlan]) -> list[DoorPlan]:
    """A door closing a loop: between two neighbours, or a second one to the spine beside the
    first (on the longer free stretch of that wall, if a door fits there)."""
    if pairs:
        return [_side_door(rng, *pairs[int(rng.integers(len(pairs)))])]
    options = []
    for door in (d for d in doors if d.axis == "y"):
        room = next(r for r in rooms if r.name == door.rooms[1])
        x0, x1 = room.rect[0], room.rect[2]
        lo, hi = door.at[0] - door.width / 2, door.at[0] + door.width / 2
        options += [(room, a, b) for a, b in ((x0, lo), (hi, x1))
                    if b - a - 2 * DOOR_END_MARGIN >= DOOR_WIDTH[0]]
    if not options:
        return []
    room, lo, hi = options[int(rng.integers(len(options)))]
    widest = min(DOOR_WIDTH[1], hi - lo - 2 * DOOR_END_MARGIN)
    width = min(snap(rng.uniform(DOOR_WIDTH[0], widest)), _floor_grid(widest))
    line = room.rect[1] if room.row == 1 else room.rect[3]
    return [DoorPlan((rooms[0].name, room.name), (_door_centre(rng, lo, hi, width), line),
                     width, "y")]


def _floor_grid(value: float) -> float:
    return round(math.floor(value / GRID + 1e-9) * GRID, 2)


def _inner_rooms(rng: np.random.Generator, rooms: list[RoomPlan],
                 style: StyleRule) -> dict[str, RoomPlan]:
    """Rooms entered only through a neighbour: {inner room name: its host room}."""
    hosts: dict[str, RoomPlan] = {}
    pairs = _neighbours(rooms)
    for i in rng.permutation(len(pairs)):
        a, b = pairs[i] if rng.random() < 0.5 else pairs[i][::-1]
        if a.name in hosts or b.name in hosts or a in hosts.values():
            continue
        if rng.random() < style.inner_share:
            hosts[a.name] = b
    if pairs and not hosts:
        hosts[pairs[0][0].name] = pairs[0][1]
    return hosts


def _neighbours(rooms: list[RoomPlan]) -> list[tuple[RoomPlan, RoomPlan]]:
    """Pairs of rooms side by side in the same row (they share a wall x = const)."""
    return [(a, b) for a in rooms[1:] for b in rooms[1:]
            if a.row == b.row and abs(a.rect[2] - b.rect[0]) < 1e-9]


def _spine_doors(rng: np.random.Generator, spine: RoomPlan, room: RoomPlan,
                 two: bool) -> list[DoorPlan]:
    """A door (or two, one in each half) in the wall a room shares with the spine."""
    x0, _, x1, _ = room.rect
    line = room.rect[1] if room.row == 1 else room.rect[3]
    spans = [(x0, (x0 + x1) / 2), ((x0 + x1) / 2, x1)] if two else [(x0, x1)]
    doors = []
    for lo, hi in spans:
        width = snap(rng.uniform(*DOOR_WIDTH))
        x = _door_centre(rng, lo, hi, width)
        doors.append(DoorPlan((spine.name, room.name), (x, line), width, "y"))
    return doors


def _side_door(rng: np.random.Generator, a: RoomPlan, b: RoomPlan) -> DoorPlan:
    """A door in the wall x = const between two rooms of the same row."""
    line = a.rect[2] if abs(a.rect[2] - b.rect[0]) < 1e-9 else a.rect[0]
    width = snap(rng.uniform(*DOOR_WIDTH))
    y = _door_centre(rng, a.rect[1], a.rect[3], width)
    return DoorPlan((a.name, b.name), (line, y), width, "x")


def _door_centre(rng: np.random.Generator, lo: float, hi: float, width: float) -> float:
    """A centre on [lo, hi] leaving DOOR_END_MARGIN between the door and the wall's ends."""
    low = lo + DOOR_END_MARGIN + width / 2
    high = hi - DOOR_END_MARGIN - width / 2
    return snap(rng.uniform(low, max(low, high)) if high > low else (lo + hi) / 2)


def _close_doors(rng: np.random.Generator, rooms: list[RoomPlan], doors: list[DoorPlan],
                 style: StyleRule) -> list[DoorPlan]:
    """Close a share of the doors, each only if all rooms stay connected through open ones."""
    names = [r.name for r in rooms]
    result = list(doors)
    closable = []
    for i in rng.permutation(len(result)):
        trial = result[:i] + [replace(result[i], open=False)] + result[i + 1:]
        if not connected(names, trial):
            continue
        closable.append(i)
        if rng.random() < style.closed_share:
            result = trial
    if closable and all(d.open for d in result):  # some door closed whenever one can be
        result[closable[0]] = replace(result[closable[0]], open=False)
    return result


def connected(rooms: list[str], doors: list[DoorPlan]) -> bool:
    """Whether every room is reachable from the first through open doors."""
    reached, frontier = {rooms[0]}, [rooms[0]]
    while frontier:
        here = frontier.pop()
        for door in doors:
            if door.open and here in door.rooms:
                other = door.rooms[1] if door.rooms[0] == here else door.rooms[0]
                if other not in reached:
                    reached.add(other)
                    frontier.append(other)
    return reached == set(rooms)
