"""Buildings in the service: where a building's memory lives under the data dir (built from
a checked id only, never from a request's path), the episode spec keys a task of a building
gets, and which world a request names (a building is always the same world)."""

from __future__ import annotations

import hashlib
import json
import re
import time
from pathlib import Path
from typing import Any

from api.config import Settings
from api.schemas import BUILDING_PATTERN, MAX_SINCE_S

_BUILDING_ID = re.compile(BUILDING_PATTERN.removeprefix("^").removesuffix("$"))


def memory_dir(settings: Settings, building: str) -> Path:
    """`DATA_DIR/buildings/ID/memory`: built here from a checked id only (ValueError for one
    that would leave the buildings directory)."""
    if not _BUILDING_ID.fullmatch(building):
        raise ValueError(f"not a building id: {building!r}")
    root = settings.buildings_dir.resolve()
    folder = (root / building / "memory").resolve()
    if folder.parent.parent != root:
        raise ValueError(f"not a building id: {building!r}")
    return folder


def building_spec(settings: Settings, building: str, since_s: Any) -> dict[str, Any]:
    """The episode spec's building keys: its memory directory, the experience store and
    its scope, and the simulated seconds since its previous task (given, or the real
    seconds since its memory was last written, at most `MAX_SINCE_S`)."""
    folder = memory_dir(settings, building)
    folder.mkdir(parents=True, exist_ok=True)
    if not isinstance(since_s, int | float) or isinstance(since_s, bool):
        try:
            written = (folder / "memory.json").stat().st_mtime
        except OSError:
            since_s = 0.0  # a first task: nothing remembered, no time passed
        else:
            since_s = round(min(max(time.time() - written, 0.0), MAX_SINCE_S), 1)
    return {"memory": str(folder), "since_s": float(since_s), "building": building,
            "experience": str(settings.experience_path.resolve())}


def world_identity(request: dict[str, Any]) -> str:
    """Which world a task's request names, as JSON: a built-in world's name, a generated
    building's arguments (less `day`, `move`, `doors`: the same building on another day), or
    an inline world file's SHA-256."""
    if request.get("world") is not None:
        found: dict[str, Any] = {"world": request["world"]}
    elif request.get("generate") is not None:
        found = {"generate": {k: v for k, v in dict(request["generate"]).items()
                              if k not in ("day", "move", "doors") and v is not None}}
    else:
        text = str(request.get("world_file") or "")
        found = {"world_file": hashlib.sha256(text.encode()).hexdigest()[:16]}
    return json.dumps(found, sort_keys=True)


def world_text(identity: str) -> str:
    found = json.loads(identity)
    if "world" in found:
        return f"world {found['world']!r}"
    if "generate" in found:
        args = ", ".join(f"{k} {v}" for k, v in found["generate"].items())
        return f"the generated building ({args})"
    return f"an inline world file (SHA-256 {found['world_file']}...)"
