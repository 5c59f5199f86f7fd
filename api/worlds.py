"""The built-in worlds clients may name in a task: the YAML files in `sim/worlds/`.

Only the file names (and room names, for display) are read here; the episode runner loads and
validates worlds. `sim` is located, not imported, so the API does not start PyBullet.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import yaml

from api.schemas import WorldPublic


def default_worlds_dir() -> Path | None:
    """`sim/worlds` next to the installed `sim` package, if there is one."""
    spec = importlib.util.find_spec("sim")
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations))) / "worlds"


def world_files(directory: Path | None) -> list[Path]:
    """The world files in `directory` (`*.yaml`, `*.yml`), sorted by name."""
    if directory is None or not directory.is_dir():
        return []
    return sorted([*directory.glob("*.yaml"), *directory.glob("*.yml")])


def world_path(directory: Path | None, name: str) -> Path | None:
    """The file of the built-in world `name`, or None if there is none."""
    return next((f for f in world_files(directory) if f.stem == name), None)


def list_worlds(directory: Path | None) -> list[WorldPublic]:
    """The worlds in `directory`, sorted by name."""
    return [WorldPublic(name=f.stem, rooms=_room_names(f)) for f in world_files(directory)]


def _room_names(path: Path) -> list[str]:
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError):
        return []
    rooms = data.get("rooms") if isinstance(data, dict) else None
    if not isinstance(rooms, list):
        return []
    return [str(r["name"]) for r in rooms if isinstance(r, dict) and "name" in r]

