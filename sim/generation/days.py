"""Days of one building: small objects move and doors open or close between consecutive days.

Day 0 is the generated building as `generate_world` makes it. Day k comes from day k-1: each
small object moves, with probability `move`, to a new placement drawn as the generator draws
them (`objects.py`: a usual placement of its label, or an unusual one with the building's
`surprise` share, weighted by the placement table, on a fitting support of another piece of
furniture, inside the top and apart from the objects there); it keeps its name and label, and
stays where it was when no other placement fits. Each door toggles with probability `doors`:
a closed one opens, an open one closes only if every room stays reachable through open doors
(the generator's rule). Furniture, walls and the robot's start never change.

Each day draws from its own streams, seeded by the building's seed, its style and the day
(objects and doors apart, so `doors` does not change where objects go), so the same arguments
give the same sequence of days.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from sim.generation.furnish import Piece
from sim.generation.layout import DoorPlan, Layout, Rect, connected
from sim.generation.objects import SmallObject, fits, free_offset
from sim.generation.table import Placement, PlacementTable

MOVE_DRAWS = 5  # new placements drawn for a moving object before it stays where it was
_OBJECTS, _DOORS = 1, 2  # the day's two streams


def day_streams(seed: int, style_code: int, day: int) -> tuple[np.random.Generator,
                                                                np.random.Generator]:
    """The random streams of one day (day >= 1): objects, doors."""
    return (np.random.default_rng([seed, style_code, day, _OBJECTS]),
            np.random.default_rng([seed, style_code, day, _DOORS]))


def next_objects(rng: np.random.Generator, table: PlacementTable, layout: Layout,
                 pieces: list[Piece], objects: list[SmallObject], surprise: float,
                 move: float) -> list[SmallObject]:
    """The small objects the day after: each moves with probability `move`."""
    result = list(objects)
    for i, obj in enumerate(objects):
        if not rng.random() < move:
            continue
        taken = {p.name: [_box(o) for j, o in enumerate(result)
                          if o.on == p.name and j != i] for p in pieces}
        moved = _move(rng, table, layout, pieces, obj, surprise, taken)
        if moved is not None:
            result[i] = moved
    return result


def _move(rng: np.random.Generator, table: PlacementTable, layout: Layout, pieces: list[Piece],
          obj: SmallObject, surprise: float, taken: dict[str, list[Rect]]
          ) -> SmallObject | None:
    """`obj` on another support, drawn as the generator draws placements; None if none fits."""
    kinds = _candidates(table, layout, pieces, obj)
    if not kinds[False] and not kinds[True]:
        return None
    for _ in range(MOVE_DRAWS):
        unusual = bool(rng.random() < surprise)
        if not kinds[unusual]:
            unusual = not unusual
        options = kinds[unusual]
        weights = np.array([p.weight for p, _ in options])
        _, supports = options[int(rng.choice(len(options), p=weights / weights.sum()))]
        support = supports[int(rng.integers(len(supports)))]
        offset = free_offset(rng, support, obj.size, taken[support.name])
        if offset is not None:
            return replace(obj, on=support.name, offset=offset, unusual=unusual)
    return None


def _candidates(table: PlacementTable, layout: Layout, pieces: list[Piece], obj: SmallObject
                ) -> dict[bool, list[tuple[Placement, list[Piece]]]]:
    """Per kind (usual False, unusual True): the placements of the object's label in each room,
    with the fitting supports there other than the one it stands on."""
    out: dict[bool, list[tuple[Placement, list[Piece]]]] = {False: [], True: []}
    for room in layout.rooms[1:]:
        for unusual in (False, True):
            for placement in table.placements_in(room.category, unusual):
                if placement.label != obj.label:
                    continue
                supports = [p for p in pieces if p.room == room.name and p.name != obj.on
                            and p.label == placement.support and fits(p, obj.size)]
                if supports:
                    out[unusual].append((placement, supports))
    return out


def _box(obj: SmallObject) -> Rect:
    dx, dy = obj.offset
    return (dx - obj.size[0] / 2, dy - obj.size[1] / 2, dx + obj.size[0] / 2,
            dy + obj.size[1] / 2)


def next_doors(rng: np.random.Generator, layout: Layout, share: float) -> Layout:
    """The doors the day after: each toggles with probability `share` (in a random order); an
    open door closes only if every room stays reachable through open doors."""
    if share <= 0:
        return layout
    names = [r.name for r in layout.rooms]
    doors: list[DoorPlan] = list(layout.doors)
    for i in (int(j) for j in rng.permutation(len(doors))):
        if not rng.random() < share:
            continue
        trial = doors[:i] + [replace(doors[i], open=not doors[i].open)] + doors[i + 1:]
        if connected(names, trial):
            doors = trial
    return replace(layout, doors=tuple(doors))
