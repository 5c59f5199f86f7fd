"""Read a world file (YAML) into a `WorldSpec`, naming the offending entry on every error.

A world is given as a built-in name (`office`, see `sim/worlds/`) or a path. Parsing checks
shapes and types and rejects unknown keys; geometry is checked by `world_checks`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from sim.errors import WorldFileError
from sim.world_checks import check_world
from sim.world_spec import (
    DoorSpec,
    FurnitureSpec,
    ObjectSpec,
    RobotSpec,
    RoomSpec,
    WorldSpec,
    normalise_category,
)

WORLDS_DIR = Path(__file__).parent / "worlds"
ROBOT_MODELS = ("pioneer", "pr2")
_TOP_KEYS = {"name", "size", "wall_height", "wall_thickness", "rooms", "doors", "furniture",
             "objects", "robot"}


class _WorldLoader(yaml.SafeLoader):
    """YAML 1.2 booleans (only true/false, so the key `on:` stays "on"); no duplicate keys."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


_WorldLoader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_WorldLoader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)


def builtin_worlds() -> list[str]:
    """Names of the worlds shipped in `sim/worlds/`."""
    return sorted(p.stem for p in WORLDS_DIR.glob("*.yaml"))


def resolve_world(source: str | Path) -> Path:
    """A built-in world name or a file path → the file path (error if neither exists)."""
    text = str(source)
    builtin = WORLDS_DIR / f"{text}.yaml"
    if "/" not in text and not text.endswith((".yaml", ".yml")) and builtin.is_file():
        return builtin
    path = Path(text)
    if path.is_file():
        return path
    raise WorldFileError(
        f"{text}: no such world file or built-in world (built-ins: {', '.join(builtin_worlds())})"
    )


def load_world_spec(source: str | Path) -> WorldSpec:
    """Read and validate a world file; raises `WorldFileError` naming file and entry."""
    path = resolve_world(source)
    label = path.name if path.parent == WORLDS_DIR else str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldFileError(f"{label}: cannot read: {exc}") from None
    return load_world_text(text, label)


def load_world_text(text: str, label: str) -> WorldSpec:
    """Read and validate a world file's YAML text; errors name `label` and the entry."""
    try:
        data = yaml.load(text, Loader=_WorldLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f":{mark.line + 1}:{mark.column + 1}" if mark is not None else ""
        raise WorldFileError(f"{label}{where}: YAML error: {exc.problem}") from None
    spec = parse_world(data, label)
    check_world(spec)
    return spec


def parse_world(data: Any, label: str) -> WorldSpec:
    """Turn the YAML document of a world file into a `WorldSpec` (types and keys only)."""
    top = _mapping(data, label, "the document", _TOP_KEYS, {"name", "size", "rooms", "robot"})
    return WorldSpec(
        name=_string(top["name"], label, "name"),
        size=_vector(top["size"], 2, label, "size", positive=True),
        wall_height=_number(top.get("wall_height", 2.0), label, "wall_height", positive=True),
        wall_thickness=_number(top.get("wall_thickness", 0.1), label, "wall_thickness",
                               positive=True),
        rooms=tuple(_room(e, label, f"rooms[{i}]") for i, e in _items(top, "rooms", label)),
        doors=tuple(_door(e, label, f"doors[{i}]") for i, e in _items(top, "doors", label)),
        furniture=tuple(
            _furniture(e, label, f"furniture[{i}]") for i, e in _items(top, "furniture", label)
        ),
        objects=tuple(_object(e, label, f"objects[{i}]") for i, e in _items(top, "objects", label)),
        robot=_robot(top["robot"], label),
        source=label,
    )


def _room(entry: Any, label: str, where: str) -> RoomSpec:
    m = _mapping(entry, label, where, {"name", "category", "rect"}, {"name", "category", "rect"})
    where = f"{where} ({m['name']})"
    rect = _vector(m["rect"], 4, label, f"{where}.rect")
    category = normalise_category(_string(m["category"], label, where))
    return RoomSpec(_string(m["name"], label, where), category, rect)


def _door(entry: Any, label: str, where: str) -> DoorSpec:
    m = _mapping(entry, label, where, {"rooms", "at", "width", "open"}, {"rooms", "at"})
    rooms = m["rooms"]
    if not isinstance(rooms, list) or len(rooms) != 2 or not all(isinstance(r, str) for r in rooms):
        raise WorldFileError(f"{label}: {where}.rooms: expected two room names, got {rooms!r}")
    where = f"{where} ({rooms[0]}/{rooms[1]})"
    is_open = m.get("open", True)
    if not isinstance(is_open, bool):
        raise WorldFileError(f"{label}: {where}.open: expected true or false, got {is_open!r}")
    return DoorSpec(
        rooms=(rooms[0], rooms[1]),
        at=_vector(m["at"], 2, label, f"{where}.at"),
        width=_number(m.get("width", 0.9), label, f"{where}.width", positive=True),
        open=is_open,
    )


def _furniture(entry: Any, label: str, where: str) -> FurnitureSpec:
    keys = {"name", "label", "room", "pose", "size"}
    m = _mapping(entry, label, where, keys, keys)
    where = f"{where} ({m['name']})"
    return FurnitureSpec(
        name=_string(m["name"], label, where),
        label=_string(m["label"], label, f"{where}.label"),
        room=_string(m["room"], label, f"{where}.room"),
        pose=_vector(m["pose"], 3, label, f"{where}.pose"),
        size=_vector(m["size"], 3, label, f"{where}.size", positive=True),
    )


def _object(entry: Any, label: str, where: str) -> ObjectSpec:
    m = _mapping(entry, label, where, {"name", "label", "on", "offset", "pose", "size"},
                 {"name", "label", "size"})
    where = f"{where} ({m['name']})"
    if ("on" in m) == ("pose" in m):
        raise WorldFileError(f"{label}: {where}: give exactly one of 'on' (a furniture name) "
                             "or 'pose' ([x, y, yaw] on the floor)")
    if "offset" in m and "on" not in m:
        raise WorldFileError(f"{label}: {where}.offset: only meaningful with 'on'")
    offset = m.get("offset", [0.0, 0.0])
    n = len(offset) if isinstance(offset, list) and len(offset) in (2, 3) else 2
    off = _vector(offset, n, label, f"{where}.offset")
    return ObjectSpec(
        name=_string(m["name"], label, where),
        label=_string(m["label"], label, f"{where}.label"),
        size=_vector(m["size"], 3, label, f"{where}.size", positive=True),
        on=_string(m["on"], label, f"{where}.on") if "on" in m else None,
        offset=(off[0], off[1], off[2] if n == 3 else 0.0),
        pose=_vector(m["pose"], 3, label, f"{where}.pose") if "pose" in m else None,
    )


def _robot(entry: Any, label: str) -> RobotSpec:
    m = _mapping(entry, label, "robot", {"model", "start"}, {"model", "start"})
    model = _string(m["model"], label, "robot.model")
    if model not in ROBOT_MODELS:
        raise WorldFileError(
            f"{label}: robot.model: unknown model {model!r} (known: {', '.join(ROBOT_MODELS)})"
        )
    return RobotSpec(model, _vector(m["start"], 3, label, "robot.start"))


def _items(top: Mapping[str, Any], key: str, label: str) -> list[tuple[int, Any]]:
    value = top.get(key, [])
    if value is None:
        return []
    if not isinstance(value, list):
        raise WorldFileError(f"{label}: {key}: expected a list, got {type(value).__name__}")
    return list(enumerate(value))


def _mapping(value: Any, label: str, where: str, allowed: set[str],
             required: set[str]) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise WorldFileError(f"{label}: {where}: expected a mapping, got {type(value).__name__}")
    unknown = sorted(str(k) for k in value if k not in allowed)
    if unknown and "(" not in where:
        where = _entry_label(where, value)
    if unknown:
        raise WorldFileError(f"{label}: {where}: unknown key {unknown[0]!r} "
                             f"(allowed: {', '.join(sorted(allowed))})")
    missing = sorted(required - set(value))
    if missing:
        raise WorldFileError(f"{label}: {where}: missing key {missing[0]!r}")
    return value


def _entry_label(where: str, value: dict[str, Any]) -> str:
    """`rooms[1]` → `rooms[1] (kitchen)` when the entry says its name (or its door's rooms)."""
    name = value.get("name")
    rooms = value.get("rooms")
    if isinstance(name, str):
        return f"{where} ({name})"
    if isinstance(rooms, list) and all(isinstance(r, str) for r in rooms):
        return f"{where} ({'/'.join(rooms)})"
    return where


def _string(value: Any, label: str, where: str) -> str:
    if not isinstance(value, str) or not value:
        raise WorldFileError(f"{label}: {where}: expected a non-empty name, got {value!r}")
    return value


def _number(value: Any, label: str, where: str, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise WorldFileError(f"{label}: {where}: expected a number, got {value!r}")
    if positive and value <= 0:
        raise WorldFileError(f"{label}: {where}: must be positive, got {value}")
    return float(value)


def _vector(value: Any, n: int, label: str, where: str, positive: bool = False) -> Any:
    if not isinstance(value, list) or len(value) != n:
        raise WorldFileError(f"{label}: {where}: expected a list of {n} numbers, got {value!r}")
    return tuple(_number(v, label, where, positive) for v in value)
