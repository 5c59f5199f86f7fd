"""The generator's placement tables (`placement.yaml` beside this file), read and validated.

A table says which styles exist, which furniture each room category holds, and where small
objects usually (and unusually) go. See the comment block of `placement.yaml`. Besides the
default table there are variants (`TABLES`), each an overlay of it that replaces the
placements of a few labels (`placement-moved.yaml`: a building whose cups, books and staplers
are not where the robot's commonsense knowledge expects them; see its header).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import yaml

from sim.errors import GenerationError

TABLE_PATH = Path(__file__).with_name("placement.yaml")
DEFAULT_TABLE = "default"
TABLES = {DEFAULT_TABLE: TABLE_PATH, "moved": Path(__file__).with_name("placement-moved.yaml")}
"""The placement tables a generated world may be built with, by name (`generate_world(...,
table=NAME)`)."""

CATEGORIES = ("corridor", "kitchen", "office", "meeting_room", "living_room", "bathroom")
"""Room categories the generator may write: the conceptual map's vocabulary (kept here, since
`sim` imports nothing of ours; a test checks it against the knowledge file)."""

Range = tuple[float, float]
AREA_UNIT = 20.0  # m^2: count ranges are per this much floor (a 40 m^2 lab draws twice)


def area_scale(rect: tuple[float, float, float, float]) -> int:
    """How many times a room draws its count ranges: its area in AREA_UNITs, at least once."""
    area = (rect[2] - rect[0]) * (rect[3] - rect[1])
    return max(1, round(area / AREA_UNIT))


@dataclass(frozen=True)
class StyleRule:
    """How a building of one style is laid out (see `styles` in placement.yaml)."""

    name: str
    rooms: tuple[int, int]
    default_rooms: tuple[int, int]
    spine: str
    spine_width: Range
    row_depth: Range
    categories: dict[str, float]
    required: tuple[str, ...]
    at_most: dict[str, int]
    inner_share: float
    extra_door_share: float
    closed_share: float


@dataclass(frozen=True)
class FurnitureRule:
    """A kind of furniture a room category holds: size ranges, how many, against a wall or free."""

    label: str
    size: tuple[Range, Range, Range]
    count: tuple[int, int]
    at: str  # "wall" or "free"


@dataclass(frozen=True)
class RoomRule:
    """Width range, small-object count range and furniture of one room category."""

    category: str
    width: Range
    objects: tuple[int, int]
    furniture: tuple[FurnitureRule, ...]


@dataclass(frozen=True)
class Placement:
    """A small object `label` on a `support` in a room of `category`, with a drawing weight."""

    category: str
    label: str
    support: str
    weight: float
    unusual: bool


@dataclass(frozen=True)
class PlacementTable:
    """The whole table: styles, room rules, small-object sizes, supports, placements."""

    styles: dict[str, StyleRule]
    rooms: dict[str, RoomRule]
    object_sizes: dict[str, tuple[float, float, float]]
    supports: frozenset[str]
    placements: tuple[Placement, ...]

    @property
    def object_labels(self) -> tuple[str, ...]:
        """The small-object vocabulary of the generator (sorted)."""
        return tuple(sorted(self.object_sizes))

    def placements_in(self, category: str, unusual: bool) -> list[Placement]:
        """The usual (or unusual) placements of a room category."""
        return [p for p in self.placements if p.category == category and p.unusual == unusual]


@cache
def placement_table(name: str = DEFAULT_TABLE) -> PlacementTable:
    """A built-in table by name (`TABLES`), read once; `GenerationError` for an unknown one."""
    if not isinstance(name, str) or name not in TABLES:
        raise GenerationError(f"table: unknown placement table {name!r} (known: "
                              f"{', '.join(TABLES)})")
    return load_table(TABLES[name])


def load_table(path: Path) -> PlacementTable:
    """Read and validate a placement table, or an overlay of one (`base`, `moved`,
    `placements`); `GenerationError` names the bad entry."""
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    try:
        if isinstance(data, dict) and "base" in data:
            data = _overlaid(path, data)
        table = _parse(data)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise GenerationError(f"{path.name}: malformed placement table: {exc!r}") from None
    _validate(table, path.name)
    return table


def _overlaid(path: Path, overlay: dict[str, Any]) -> dict[str, Any]:
    """The base table's data with the overlay's `moved` labels' placement rows replaced by
    the overlay's rows (added after the base's rows of the same category and kind)."""
    unknown = set(overlay) - {"base", "moved", "placements"}
    if unknown:
        raise GenerationError(f"{path.name}: unknown keys {sorted(unknown)} in an overlay "
                              "(base, moved, placements)")
    base = yaml.safe_load(path.with_name(str(overlay["base"])).read_text(encoding="utf-8"))
    moved = {str(label) for label in overlay["moved"]}
    placements: dict[str, dict[str, list[Any]]] = {
        cat: {kind: [row for row in rows if str(row[0]) not in moved]
              for kind, rows in kinds.items()}
        for cat, kinds in base["placements"].items()}
    for cat, kinds in overlay["placements"].items():
        for kind, rows in kinds.items():
            if kind not in ("usual", "unusual"):
                raise GenerationError(f"{path.name}: placements.{cat}: {kind!r} is not usual "
                                      "or unusual")
            for row in rows:
                if str(row[0]) not in moved:
                    raise GenerationError(f"{path.name}: placements.{cat}.{kind}: {row!r}: "
                                          f"label {row[0]!r} is not one of the moved labels "
                                          f"({', '.join(sorted(moved))})")
            placements.setdefault(cat, {}).setdefault(kind, []).extend(rows)
    return {**base, "placements": placements}


def _parse(data: dict[str, Any]) -> PlacementTable:
    styles = {name: _style(name, s) for name, s in data["styles"].items()}
    rooms = {cat: _room(cat, r) for cat, r in data["rooms"].items()}
    sizes = {label: _triple(size) for label, size in data["objects"].items()}
    placements = tuple(
        Placement(cat, str(row[0]), str(row[1]), float(row[2]), kind == "unusual")
        for cat, kinds in data["placements"].items()
        for kind, rows in kinds.items()
        for row in rows
    )
    return PlacementTable(styles, rooms, sizes, frozenset(data["supports"]), placements)


def _style(name: str, s: dict[str, Any]) -> StyleRule:
    return StyleRule(
        name=name, rooms=_int_pair(s["rooms"]), default_rooms=_int_pair(s["default_rooms"]),
        spine=str(s["spine"]), spine_width=_pair(s["spine_width"]),
        row_depth=_pair(s["row_depth"]),
        categories={str(c): float(w) for c, w in s["categories"].items()},
        required=tuple(s["required"]),
        at_most={str(c): int(n) for c, n in s.get("at_most", {}).items()},
        inner_share=float(s["inner_share"]),
        extra_door_share=float(s["extra_door_share"]), closed_share=float(s["closed_share"]),
    )


def _room(category: str, r: dict[str, Any]) -> RoomRule:
    furniture = tuple(
        FurnitureRule(str(f["label"]), (_pair(f["size"][0]), _pair(f["size"][1]),
                                        _pair(f["size"][2])), _int_pair(f["count"]), str(f["at"]))
        for f in r["furniture"]
    )
    return RoomRule(category, _pair(r["width"]), _int_pair(r["objects"]), furniture)


def _pair(value: Any) -> Range:
    low, high = float(value[0]), float(value[1])
    if not 0 <= low <= high or len(value) != 2:
        raise ValueError(f"expected a range [low, high], got {value!r}")
    return (low, high)


def _int_pair(value: Any) -> tuple[int, int]:
    low, high = _pair(value)
    return (int(low), int(high))


def _triple(value: Any) -> tuple[float, float, float]:
    if len(value) != 3:
        raise ValueError(f"expected [x, y, z], got {value!r}")
    return (float(value[0]), float(value[1]), float(value[2]))


def _validate(table: PlacementTable, source: str) -> None:
    """Categories from the vocabulary, known supports and labels, wall/free placement."""
    for style in table.styles.values():
        uncapped = [c for c in style.categories if c not in style.at_most]
        if not uncapped:
            raise GenerationError(f"{source}: styles.{style.name}: every category is capped "
                                  "by at_most; leave one uncapped")
        for cat in (*style.categories, *style.required, *style.at_most):
            if cat not in table.rooms or cat not in CATEGORIES:
                raise GenerationError(f"{source}: styles.{style.name}: unknown category {cat!r}")
    for rule in table.rooms.values():
        if rule.category not in CATEGORIES:
            raise GenerationError(f"{source}: rooms.{rule.category}: not a known category "
                                  f"(known: {', '.join(CATEGORIES)})")
        for f in rule.furniture:
            if f.at not in ("wall", "free"):
                raise GenerationError(f"{source}: rooms.{rule.category}: {f.label}.at must be "
                                      f"wall or free, got {f.at!r}")
    for p in table.placements:
        if p.support not in table.supports or p.label not in table.object_sizes:
            raise GenerationError(f"{source}: placements.{p.category}: [{p.label}, {p.support}]"
                                  ": unknown object label or support")
