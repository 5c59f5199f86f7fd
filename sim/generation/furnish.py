"""Furniture for every room of a layout, from the placement table's room rules.

Pieces stand against a wall or free in the room, never overlap, keep the strip in front of
every door free, and are only kept if the larger robot can still get from each door of the
room to every other door and within reach of every piece.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim.generation.freespace import approach_point, door_zone, free_space, passable
from sim.generation.layout import DoorPlan, Layout, Rect, RoomPlan
from sim.generation.table import FurnitureRule, PlacementTable, RoomRule, area_scale

WALL_GAP = 0.08  # room border (wall centre line) to a piece: half a wall plus 3 cm
PIECE_GAP = 0.05  # between two pieces
FREE_MARGIN = 0.3  # a free-standing piece keeps this far from the walls
TRIES = 25  # attempts per piece before it is left out
QUARTER = 1.5708  # yaw of a piece turned to stand along a wall x = const

_Fit = tuple[tuple[float, float, float], tuple[float, float, float], Rect]  # pose, size, box


@dataclass(frozen=True)
class Piece:
    """A placed furniture box: world-file fields plus its axis-aligned footprint `box`."""

    name: str
    label: str
    room: str
    pose: tuple[float, float, float]
    size: tuple[float, float, float]
    box: Rect


def furnish(rng: np.random.Generator, layout: Layout, table: PlacementTable) -> list[Piece]:
    """Furniture of every room but the spine (which stays clear for driving)."""
    counters: dict[str, int] = {}
    pieces: list[Piece] = []
    for room in layout.rooms[1:]:
        doors = [d for d in layout.doors if room.name in d.rooms]
        pieces += _furnish_room(rng, room, table.rooms[room.category], doors, counters)
    return pieces


def _furnish_room(rng: np.random.Generator, room: RoomPlan, rule: RoomRule,
                  doors: list[DoorPlan], counters: dict[str, int]) -> list[Piece]:
    zones = [door_zone(room.rect, d) for d in doors]
    entries = [approach_point(room.rect, d) for d in doors]
    placed: list[Piece] = []
    scale = area_scale(room.rect)
    for furniture in rule.furniture:
        low, high = furniture.count
        for _ in range(sum(int(rng.integers(low, high + 1)) for _ in range(scale))):
            fit = _place(rng, room, furniture, zones, entries, placed)
            if fit is None:
                continue
            label = furniture.label
            counters[label] = counters.get(label, 0) + 1
            placed.append(Piece(f"{label}{counters[label]}", label, room.name, *fit))
    return placed


def _place(rng: np.random.Generator, room: RoomPlan, rule: FurnitureRule, zones: list[Rect],
           entries: list[tuple[float, float]], placed: list[Piece]) -> _Fit | None:
    """Try TRIES random poses; the first that fits and keeps the room passable wins."""
    for _ in range(TRIES):
        size = tuple(round(float(rng.uniform(*r)), 2) for r in rule.size)
        pose_box = (_against_wall if rule.at == "wall" else _free)(rng, room.rect, size)
        if pose_box is None:
            continue
        pose, box = pose_box
        if any(_overlap(box, z, 0.0) for z in zones):
            continue
        if any(_overlap(box, p.box, PIECE_GAP) for p in placed):
            continue
        boxes = [p.box for p in placed] + [box]
        if passable(free_space(room.rect, boxes), entries, boxes):
            return pose, (size[0], size[1], size[2]), box
    return None


def _against_wall(rng: np.random.Generator, rect: Rect, size: tuple[float, ...]
                  ) -> tuple[tuple[float, float, float], Rect] | None:
    """A pose with the piece's back (its size-y side) against one of the four walls."""
    x0, y0, x1, y1 = rect
    sx, sy = size[0], size[1]
    wall = ("south", "north", "west", "east")[int(rng.integers(4))]
    along = (x0, x1) if wall in ("south", "north") else (y0, y1)
    if along[1] - along[0] - 2 * WALL_GAP < sx:
        return None
    c = float(rng.uniform(along[0] + WALL_GAP + sx / 2, along[1] - WALL_GAP - sx / 2))
    if wall == "south":
        box = (c - sx / 2, y0 + WALL_GAP, c + sx / 2, y0 + WALL_GAP + sy)
    elif wall == "north":
        box = (c - sx / 2, y1 - WALL_GAP - sy, c + sx / 2, y1 - WALL_GAP)
    elif wall == "west":
        box = (x0 + WALL_GAP, c - sx / 2, x0 + WALL_GAP + sy, c + sx / 2)
    else:
        box = (x1 - WALL_GAP - sy, c - sx / 2, x1 - WALL_GAP, c + sx / 2)
    yaw = 0.0 if wall in ("south", "north") else QUARTER
    return _rounded(box, yaw)


def _free(rng: np.random.Generator, rect: Rect, size: tuple[float, ...]
          ) -> tuple[tuple[float, float, float], Rect] | None:
    """A pose anywhere in the room, turned by 0 or 90 degrees, FREE_MARGIN from the walls."""
    turned = rng.random() < 0.5
    w, h = (size[1], size[0]) if turned else (size[0], size[1])
    x0, y0, x1, y1 = rect
    lo_x, hi_x = x0 + FREE_MARGIN + w / 2, x1 - FREE_MARGIN - w / 2
    lo_y, hi_y = y0 + FREE_MARGIN + h / 2, y1 - FREE_MARGIN - h / 2
    if hi_x < lo_x or hi_y < lo_y:
        return None
    cx, cy = float(rng.uniform(lo_x, hi_x)), float(rng.uniform(lo_y, hi_y))
    return _rounded((cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2), QUARTER if turned else 0.0)


def _rounded(box: Rect, yaw: float) -> tuple[tuple[float, float, float], Rect]:
    """Pose (centre rounded to mm) and the footprint box around the rounded centre."""
    cx, cy = round((box[0] + box[2]) / 2, 3), round((box[1] + box[3]) / 2, 3)
    hw, hh = (box[2] - box[0]) / 2, (box[3] - box[1]) / 2
    return (cx, cy, yaw), (cx - hw, cy - hh, cx + hw, cy + hh)


def _overlap(a: Rect, b: Rect, gap: float) -> bool:
    """Whether two boxes come closer than `gap` (touching at gap 0 does not count)."""
    return (a[0] < b[2] + gap and b[0] < a[2] + gap
            and a[1] < b[3] + gap and b[1] < a[3] + gap)
