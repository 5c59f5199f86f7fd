"""Deterministic floor-plan generator: a seed and a style → a valid world file.

A building is a spine (corridor or hall) with a row of rooms on each side; rooms of varied size
and aspect get doors (0.8–1.2 m) on shared walls, some only to a neighbour room, some closed
(only where every room stays reachable through open doors); furniture and small objects come from
the placement table (`sim/generation/placement.yaml`), a share `surprise` of the objects placed
where the conceptual map's knowledge rates them unlikely. See sim/README.md ("Generated worlds").

    world = generate_world(seed=7, style="office", rooms=6)
    spec = world.spec()                 # through sim's own loader and checks
    targets = world.targets(rng_seed=0)  # two labels present, one absent
    later = generate_world(seed=7, style="office", rooms=6, day=3, move=0.2, doors=0.1)

Day k > 0 of a building is day k-1 with some small objects moved and some doors toggled
(`sim/generation/days.py`); day 0 is the building as generated.
"""

from __future__ import annotations

import math
import re
import zlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sim.errors import GenerationError
from sim.generation.days import day_streams, next_doors, next_objects
from sim.generation.freespace import approach_point, free_space
from sim.generation.furnish import Piece, furnish
from sim.generation.layout import Layout, plan_layout
from sim.generation.objects import SmallObject, place_objects
from sim.generation.table import DEFAULT_TABLE, PlacementTable, StyleRule, placement_table
from sim.world_file import ROBOT_MODELS, load_world_text
from sim.world_spec import WorldSpec

STYLES = ("office", "apartment", "lab")
WITHHELD_LABELS = 2  # small-object labels kept out of every world, so some are always absent
MIN_PRESENT_LABELS = 2  # different small-object labels a world should hold (benchmark targets)
PLACEMENT_ATTEMPTS = 10
WALL_HEIGHT = 2.0
DEFAULT_MOVE = 0.2  # per day, the probability each small object moves (days after day 0)
DEFAULT_DOORS = 0.0  # per day, the probability each door toggles open / closed


@dataclass(frozen=True)
class GeneratedWorld:
    """A generated world: the world-file mapping `data` and what the generator knows of it."""

    data: dict[str, Any] = field(hash=False)
    seed: int
    style: str
    surprises: tuple[str, ...] = ()  # names of objects placed where the knowledge says unlikely
    surprise: float = 0.25  # the share asked for
    day: int = 0  # days after the building was generated (objects moved, doors toggled)
    move: float = DEFAULT_MOVE  # per day, the probability each small object moves
    doors: float = DEFAULT_DOORS  # per day, the probability each door toggles
    table: str = DEFAULT_TABLE  # the placement table it was built with (`generation/table.py`)

    def yaml(self) -> str:
        """The world file as YAML text (docs/architecture.md's format), headed by its command."""
        command = (f"avs world generate --seed {self.seed} --style {self.style} --rooms "
                   f"{len(self.data['rooms']) - 1} --surprise {self.surprise!r} --robot "
                   f"{self.data['robot']['model']}")
        if self.day:
            command += f" --day {self.day} --move {self.move!r} --doors {self.doors!r}"
        if self.table != DEFAULT_TABLE:
            command += f" --table {self.table}"
        return world_yaml(self.data, command)

    def spec(self) -> WorldSpec:
        """The world parsed and checked by sim's own world-file loader."""
        return load_world_text(self.yaml(), f"{self.data['name']}.yaml")

    def labels_present(self) -> list[str]:
        """Labels of the small objects in the world (sorted, each once)."""
        return sorted({o["label"] for o in self.data["objects"]})

    def targets(self, rng_seed: int, present: int = 2, absent: int = 1) -> list[str]:
        """`present` labels of objects in the world, then `absent` labels of the generator's
        vocabulary that are not in it (a benchmark's targets for this world)."""
        rng = np.random.default_rng(rng_seed)
        here = self.labels_present()
        missing = sorted(set(placement_table(self.table).object_labels) - set(here))
        if present > len(here) or absent > len(missing) or min(present, absent) < 0:
            raise GenerationError(f"{self.data['name']}: cannot pick {present} present and "
                                  f"{absent} absent labels (present: {', '.join(here)}; "
                                  f"absent: {', '.join(missing)})")
        return ([str(x) for x in rng.choice(here, present, replace=False)]
                + [str(x) for x in rng.choice(missing, absent, replace=False)])


def generate_world(seed: int, style: str = "office", rooms: int | None = None,
                   surprise: float = 0.25, robot: str = "pioneer", day: int = 0,
                   move: float = DEFAULT_MOVE, doors: float = DEFAULT_DOORS,
                   table: str = DEFAULT_TABLE) -> GeneratedWorld:
    """A world for `seed` (same arguments, same world); `rooms` counts the rooms off the spine.

    `day` k > 0 is the same building k days later: each day every small object moves with
    probability `move` and every door toggles with probability `doors` (`generation/days.py`);
    day 0 is the building as generated, whatever `move` and `doors` say. `table` names the
    placement table (`generation/table.py`, `TABLES`): `default`, or `moved` (a building whose
    cups, books and staplers are elsewhere than the robot's knowledge expects; the world is
    named `<style>_<seed>_moved`)."""
    table_name = table
    table = placement_table(table_name)
    rule = _check_arguments(table, seed, style, rooms, surprise, robot)
    _check_days(day, move, doors)
    code = zlib.crc32(style.encode())
    rng = np.random.default_rng([seed, code])
    drawn = int(rng.integers(rule.default_rooms[0], rule.default_rooms[1] + 1))
    count = drawn if rooms is None else rooms  # drawn either way: --rooms K of a drawn K agrees
    layout = plan_layout(rng, table, rule, count)
    pieces = furnish(rng, layout, table)
    objects = _small_objects(rng, table, layout, pieces, surprise)
    start = _start(rng, layout, pieces)
    for k in range(1, day + 1):
        objects_rng, doors_rng = day_streams(seed, code, k)
        objects = next_objects(objects_rng, table, layout, pieces, objects, surprise, move)
        layout = next_doors(doors_rng, layout, doors)
    name = f"{style}_{seed}" + ("" if table_name == DEFAULT_TABLE else f"_{table_name}")
    data = world_data(name, layout, pieces, objects, robot, start)
    if not day:
        move, doors = DEFAULT_MOVE, DEFAULT_DOORS  # day 0 is the same world whatever they say
    return GeneratedWorld(data, seed, style, tuple(o.name for o in objects if o.unusual),
                          float(surprise), day, float(move), float(doors), table_name)


def _small_objects(rng: np.random.Generator, table: PlacementTable, layout: Layout,
                   pieces: list[Piece], surprise: float) -> list[SmallObject]:
    """Small objects with WITHHELD_LABELS labels kept out, drawn again (a few times at most)
    until at least MIN_PRESENT_LABELS different labels are in the world."""
    for _ in range(PLACEMENT_ATTEMPTS):
        withheld = frozenset(str(x) for x in rng.choice(table.object_labels, WITHHELD_LABELS,
                                                        replace=False))
        objects = place_objects(rng, table, layout, pieces, surprise, withheld)
        if len({o.label for o in objects}) >= MIN_PRESENT_LABELS:
            break
    return objects


def _check_arguments(table: PlacementTable, seed: int, style: str, rooms: int | None,
                     surprise: float, robot: str) -> StyleRule:
    """The style's rule, or `GenerationError` naming the bad argument."""
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise GenerationError(f"seed: expected a non-negative integer, got {seed!r}")
    if style not in table.styles:
        raise GenerationError(f"style: unknown style {style!r} (known: {', '.join(STYLES)})")
    rule = table.styles[style]
    low, high = rule.rooms
    if rooms is not None and (isinstance(rooms, bool) or not isinstance(rooms, int)
                              or not low <= rooms <= high):
        raise GenerationError(f"rooms: style {style} takes {low} to {high} rooms off its "
                              f"{rule.spine}, got {rooms!r}")
    if isinstance(surprise, bool) or not isinstance(surprise, int | float) or not (
            math.isfinite(surprise) and 0.0 <= surprise <= 1.0):
        raise GenerationError(f"surprise: expected a share in [0, 1], got {surprise!r}")
    if robot not in ROBOT_MODELS:
        raise GenerationError(f"robot: unknown model {robot!r} (known: {', '.join(ROBOT_MODELS)})")
    return rule


def _check_days(day: int, move: float, doors: float) -> None:
    """`GenerationError` naming the bad argument of a day's world."""
    if isinstance(day, bool) or not isinstance(day, int) or day < 0:
        raise GenerationError(f"day: expected a non-negative integer, got {day!r}")
    for name, value in (("move", move), ("doors", doors)):
        if isinstance(value, bool) or not isinstance(value, int | float) or not (
                math.isfinite(value) and 0.0 <= value <= 1.0):
            raise GenerationError(f"{name}: expected a probability in [0, 1], got {value!r}")


def _start(rng: np.random.Generator, layout: Layout,
           pieces: list[Piece]) -> tuple[float, float, float]:
    """A free pose in a random room (or the spine) where the larger robot footprint fits."""
    room = layout.rooms[int(rng.integers(len(layout.rooms)))]
    boxes = [p.box for p in pieces if p.room == room.name]
    space = free_space(room.rect, boxes)
    door = next(d for d in layout.doors if room.name in d.rooms)
    label = space.label_at(*approach_point(room.rect, door))
    if label == 0:  # furnishing keeps every door's approach free; this would be a bug
        raise GenerationError(f"{room.name}: no free space in front of its door {door.rooms}")
    cells = space.cells_of(label)
    x, y = cells[int(rng.integers(len(cells)))]
    return (round(x, 2), round(y, 2), round(float(rng.uniform(-math.pi, math.pi)), 2))


def world_data(name: str, layout: Layout, pieces: list[Piece], objects: list[SmallObject],
               robot: str, start: tuple[float, float, float]) -> dict[str, Any]:
    """The world-file mapping (docs/architecture.md's format) of a generated building."""
    return {
        "name": name,
        "size": list(layout.size),
        "wall_height": WALL_HEIGHT,
        "rooms": [{"name": r.name, "category": r.category, "rect": list(r.rect)}
                  for r in layout.rooms],
        "doors": [{"rooms": list(d.rooms), "at": list(d.at), "width": d.width, "open": d.open}
                  for d in layout.doors],
        "furniture": [{"name": p.name, "label": p.label, "room": p.room, "pose": list(p.pose),
                       "size": list(p.size)} for p in pieces],
        "objects": [{"name": o.name, "label": o.label, "on": o.on, "offset": list(o.offset),
                     "size": list(o.size)} for o in objects],
        "robot": {"model": robot, "start": list(start)},
    }


def world_yaml(data: dict[str, Any], origin: str) -> str:
    """YAML text of a world mapping: one flow-style line per entry, like sim/worlds/*.yaml."""
    lines = [f"# Generated by sim.generate: {origin}", f"name: {_flow(data['name'])}",
             f"size: {_flow(data['size'])}", f"wall_height: {_flow(data['wall_height'])}"]
    for key in ("rooms", "doors", "furniture", "objects"):
        lines.append(f"{key}:" if data[key] else f"{key}: []")
        lines += [f"  - {_flow(entry)}" for entry in data[key]]
    lines.append(f"robot: {_flow(data['robot'])}")
    return "\n".join(lines) + "\n"


_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def _flow(value: Any) -> str:
    """A YAML flow scalar, sequence or mapping (names quoted unless they are plain words)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(round(float(value), 4))
    if isinstance(value, str):
        plain = _PLAIN.match(value) and value.lower() not in ("true", "false", "null")
        return value if plain else '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_flow(v)}" for k, v in value.items()) + "}"
    return "[" + ", ".join(_flow(v) for v in value) + "]"
