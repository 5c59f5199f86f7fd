"""Small objects on furniture tops, from the placement table, with a share of surprises.

Each room with a support gets a few object slots; a share `surprise` of all slots (rounded at
random, so the mean is exact) is filled from the room category's unusual placements, the rest
from its usual ones. Labels withheld from the world are never placed, so a benchmark always has
labels that are absent from the building.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.generation.furnish import Piece
from sim.generation.layout import Layout, Rect, RoomPlan
from sim.generation.table import Placement, PlacementTable, area_scale

EDGE = 0.02  # an object keeps this far inside the edge of its support's top
OBJECT_GAP = 0.02  # between two objects on one top
TRIES = 20


@dataclass(frozen=True)
class SmallObject:
    """A placed small object: world-file fields, and whether its placement is unusual."""

    name: str
    label: str
    on: str
    offset: tuple[float, float]
    size: tuple[float, float, float]
    unusual: bool


@dataclass(frozen=True)
class _Slot:
    """Room for one object: the usual and unusual placements that can be made there."""

    room: RoomPlan
    usual: tuple[Placement, ...]
    unusual: tuple[Placement, ...]


def place_objects(rng: np.random.Generator, table: PlacementTable, layout: Layout,
                  pieces: list[Piece], surprise: float,
                  withheld: frozenset[str]) -> list[SmallObject]:
    """Fill slots in every room: about `surprise` of them from unusual placements."""
    slots = _slots(rng, table, layout, pieces, withheld)
    taken: dict[str, list[Rect]] = {}
    counters: dict[str, int] = {}
    result = []
    for slot, unusual in _choose_surprises(rng, slots, surprise):
        options = slot.unusual if unusual else slot.usual
        weights = np.array([p.weight for p in options])
        placement = options[int(rng.choice(len(options), p=weights / weights.sum()))]
        size = table.object_sizes[placement.label]
        supports = [p for p in pieces if p.room == slot.room.name
                    and p.label == placement.support and fits(p, size)]
        support = supports[int(rng.integers(len(supports)))]
        offset = free_offset(rng, support, size, taken.setdefault(support.name, []))
        if offset is None:
            continue
        counters[placement.label] = counters.get(placement.label, 0) + 1
        name = f"{placement.label}{counters[placement.label]}"
        result.append(SmallObject(name, placement.label, support.name, offset, size, unusual))
    return result


def _slots(rng: np.random.Generator, table: PlacementTable, layout: Layout, pieces: list[Piece],
           withheld: frozenset[str]) -> list[_Slot]:
    """Object slots per room (the table's count range), where some placement is possible."""
    slots = []
    for room in layout.rooms[1:]:
        here = [p for p in pieces if p.room == room.name]
        usual, unusual = (tuple(_possible(table, room.category, kind, here, withheld))
                          for kind in (False, True))
        if not usual and not unusual:
            continue
        low, high = table.rooms[room.category].objects
        count = sum(int(rng.integers(low, high + 1)) for _ in range(area_scale(room.rect)))
        slots += [_Slot(room, usual, unusual)] * count
    return slots


def _possible(table: PlacementTable, category: str, unusual: bool, here: list[Piece],
              withheld: frozenset[str]) -> list[Placement]:
    """Placements of a category whose label is allowed and whose support is in the room."""
    return [p for p in table.placements_in(category, unusual) if p.label not in withheld
            and any(f.label == p.support and fits(f, table.object_sizes[p.label]) for f in here)]


def _choose_surprises(rng: np.random.Generator, slots: list[_Slot],
                      share: float) -> list[tuple[_Slot, bool]]:
    """Mark a share of the slots unusual (random rounding, so the mean is exact).

    A slot that allows only usual (or only unusual) placements cannot be switched; when there
    are too many of them for the share, some of them are left empty instead.
    """
    order = [int(i) for i in rng.permutation(len(slots))]
    only_usual = [i for i in order if not slots[i].unusual]
    only_unusual = [i for i in order if not slots[i].usual]
    both = [i for i in order if slots[i].usual and slots[i].unusual]
    fixed = len(only_unusual) + len(both)
    if share > 0 and share * (len(only_usual) + fixed) > fixed:
        only_usual = only_usual[:math.floor(fixed * (1 - share) / share + 1e-9)]
    free = len(only_usual) + len(both)
    if share < 1 and share * (free + len(only_unusual)) < len(only_unusual):
        only_unusual = only_unusual[:math.floor(share * free / (1 - share) + 1e-9)]
    total = len(only_usual) + len(only_unusual) + len(both)
    wanted = math.floor(share * total)
    wanted += int(rng.random() < share * total - wanted)
    chosen = set(only_unusual) | set(both[:max(0, wanted - len(only_unusual))])
    kept = sorted(only_usual + only_unusual + both)
    return [(slots[i], i in chosen) for i in kept]


def fits(support: Piece, size: tuple[float, float, float]) -> bool:
    return (support.size[0] - 2 * EDGE >= size[0] and support.size[1] - 2 * EDGE >= size[1])


def free_offset(rng: np.random.Generator, support: Piece, size: tuple[float, float, float],
            taken: list[Rect]) -> tuple[float, float] | None:
    """An offset on the support's top (its own frame) clear of the objects already there."""
    limit_x = _floor_cm(support.size[0] / 2 - size[0] / 2 - EDGE)
    limit_y = _floor_cm(support.size[1] / 2 - size[1] / 2 - EDGE)
    for _ in range(TRIES):
        dx = round(float(rng.uniform(-limit_x, limit_x)), 2)
        dy = round(float(rng.uniform(-limit_y, limit_y)), 2)
        box = (dx - size[0] / 2, dy - size[1] / 2, dx + size[0] / 2, dy + size[1] / 2)
        if all(_apart(box, other) for other in taken):
            taken.append(box)
            return (dx, dy)
    return None


def _floor_cm(value: float) -> float:
    return math.floor(max(value, 0.0) * 100) / 100


def _apart(a: Rect, b: Rect) -> bool:
    return (a[2] + OBJECT_GAP <= b[0] or b[2] + OBJECT_GAP <= a[0]
            or a[3] + OBJECT_GAP <= b[1] or b[3] + OBJECT_GAP <= a[1])
