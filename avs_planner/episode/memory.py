"""A building's memory: what the robot learned in one task there, kept for the next.

A service robot works in the same building day after day. At the end of a task it keeps what
its own sensors told it (never the simulator's truth): the occupancy grid, the place map
(places, the paths between them, door openings, rooms), what the place classifier said at
each place, and the objects it confirmed, each with the building time it was seen. The next
task in that building starts from it (`recall`):

- the grid, places, doors and rooms are the robot's map again; a wall or door that changed
  since is re-mapped by the laser as any cell is (hits and misses move its log-odds);
- furniture (labels the knowledge's `mobility` section says are moved less than
  `fixed_below` times a day) that is still likely in place (P = exp(-rate x days) at least
  `KEEP_FURNITURE`) is a known object again, and evidence for its room's category;
- every other object is a *sighting*, weighted by the same decay (`Sighting.weight`). A
  sighting is never a known object, so nothing is ever reported from memory alone: a task
  checks it by looking again (`episode/recall.py`), and one not seen where it was is dropped.

Stored as two files in the building's directory: `memory.json` (the map's entities, the
evidence and the objects, plain JSON) and the grid it names, `grid-<tasks>.npz` (the grid's
arrays, read without pickle). The grid is written first under a new name, then
`memory.json` is replaced: a task stopped in between leaves the memory as it was. The
directory is given by whoever runs the task (the CLI's `--memory DIR`, a
campaign's own output directory, the service's data directory); nothing here builds a path
from a request.
"""

from __future__ import annotations

import json
import math
import os
import re
import tempfile
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.mind import Mind
from conceptual_map.errors import MapError
from conceptual_map.metric import OccupancyGrid
from conceptual_map.places import PlaceMap

FORMAT = 1
MEMORY_FILE = "memory.json"
GRID_FILE = re.compile(r"grid-[0-9]{1,9}\.npz")  # the grid files memory.json may name
DAY_S = 86400.0
KEEP_FURNITURE = 0.5  # furniture more likely moved than not is not a known object any more
FORGET_BELOW = 0.01  # a sighting this unlikely to hold is not kept


class BuildingMemoryError(EpisodeError):
    """A building memory that cannot be read or written; the message names the file."""


@dataclass(frozen=True)
class Sighting:
    """An object seen in an earlier task: where, when (building seconds), and P(it has not
    been moved since) at the start of this task (`weight`)."""

    label: str
    position: tuple[float, float, float]
    seen_at: float
    weight: float = 1.0
    support: str | None = None  # the label it stood on, for the trace

    def to_json(self) -> dict[str, Any]:
        return {"label": self.label, "position": [round(v, 3) for v in self.position],
                "seen_at": round(self.seen_at, 3), "weight": round(self.weight, 4),
                "support": self.support}


@dataclass
class BuildingMemory:
    """What is kept of a building between tasks (see the module's doc)."""

    tasks: int = 0
    clock: float = 0.0  # building seconds at the end of the last task
    grid_origin: tuple[float, float] = (0.0, 0.0)
    grid_logodds: np.ndarray | None = field(default=None, repr=False)
    grid_resolution: float = 0.05
    place_map: dict[str, Any] = field(default_factory=dict)
    evidence: dict[str, Any] = field(default_factory=dict)
    objects: list[dict[str, Any]] = field(default_factory=list)  # kept known objects
    sightings: list[dict[str, Any]] = field(default_factory=list)  # not checked yet
    saved: str = ""  # date and time written (UTC, ISO 8601)

    def summary(self) -> dict[str, Any]:
        """What is remembered, in short (the service's building page, `avs` output)."""
        labels: dict[str, int] = {}
        for obj in (*self.objects, *self.sightings):
            labels[obj["label"]] = labels.get(obj["label"], 0) + 1
        return {"tasks": self.tasks, "clock_s": round(self.clock, 1), "saved": self.saved,
                "places": len(self.place_map.get("places", {})),
                "rooms": len(self.place_map.get("rooms", {})),
                "doors": len(self.place_map.get("openings", {})),
                "objects": len(self.objects), "sightings": len(self.sightings),
                "labels": dict(sorted(labels.items())),
                "last_seen": {o["label"]: o["seen_at"] for o in sorted(
                    (*self.objects, *self.sightings), key=lambda o: o["seen_at"])}}


def remember(mind: Mind, previous: BuildingMemory | None, start: float,
             same_spot: float = 1.0) -> BuildingMemory:
    """The memory after a task that began at building time `start` (the mind's clock counts
    from there): its map, evidence and objects, and the sightings it did not check.

    A sighting is superseded by a later one of its label within `same_spot` m (the
    executor's `same_object`): by an object of the mind (seen, or recalled furniture, in
    this task), or by a newer sighting not checked either. An object seen at the same spot
    task after task (a plant nobody searches for) is then remembered once, at its latest,
    instead of once per task."""
    grid = mind.grid
    objects, index = [], {}
    for oid, obj in mind.objects.items():
        index[oid] = len(objects)
        objects.append({"label": obj.label, "position": [round(v, 3) for v in obj.position],
                        "support": index.get(obj.support) if obj.support else None,
                        "seen_at": round(start + mind.seen_at.get(oid, mind.clock), 3)})
    sightings = [s.to_json() for s in _latest(mind, same_spot)]
    return BuildingMemory(
        tasks=(previous.tasks if previous is not None else 0) + 1,
        clock=start + mind.clock,
        grid_origin=(float(grid.origin[0]), float(grid.origin[1])),
        grid_logodds=grid.logodds.copy(), grid_resolution=grid.resolution,
        place_map=mind.place_map.export(), evidence=mind.cmap.graph.place_evidence(),
        objects=objects, sightings=sightings,
        saved=datetime.now(UTC).isoformat(timespec="seconds"))


def _latest(mind: Mind, same_spot: float) -> list[Sighting]:
    """The mind's unchecked sightings less those superseded (`remember`), oldest first."""
    def near(label: str, position: tuple[float, ...], other_label: str,
             other: tuple[float, ...]) -> bool:
        return label == other_label and math.dist(position[:2], other[:2]) <= same_spot

    kept: list[Sighting] = []
    for s in sorted((s for s in mind.remembered if isinstance(s, Sighting)),
                    key=lambda s: -s.seen_at):
        if any(near(s.label, s.position, o.label, o.position) for o in mind.objects.values()):
            continue
        if any(near(s.label, s.position, k.label, k.position) for k in kept):
            continue
        kept.append(s)
    return kept[::-1]


def recall(mind: Mind, memory: BuildingMemory, start: float) -> dict[str, Any]:
    """Put `memory` into a fresh `mind` for a task beginning at building time `start`; the
    mind's clock counts from `start` (objects keep their age as a negative `seen_at`).
    Returns what was recalled (the trace's `memory` event)."""
    if mind.place_map.places or mind.objects:
        raise BuildingMemoryError("a building memory is recalled into a fresh mind only")
    if memory.grid_logodds is None:
        raise BuildingMemoryError("the building memory holds no grid")
    if not math.isclose(memory.grid_resolution, mind.grid.resolution):
        raise BuildingMemoryError(
            f"the building memory's grid has {memory.grid_resolution} m cells; this robot "
            f"maps with {mind.grid.resolution} m")
    mobility = mind.cmap.knowledge.mobility
    mind.grid = OccupancyGrid.restored(memory.grid_origin, memory.grid_logodds,
                                       memory.grid_resolution, mind.grid.model)
    try:
        mind.place_map, events = PlaceMap.restored(memory.place_map, mind.config)
        mind._feed.apply(events)
        for place, kinds in memory.evidence.items():
            if not mind.cmap.graph.has_place(place):
                continue
            for kind, weights in kinds.items():
                mind.cmap.observe_property(place, kind, weights)
            mind.classified.add(place)
    except (MapError, TypeError, ValueError) as exc:
        raise BuildingMemoryError(f"the building memory's map cannot be restored: {exc}") from None
    kept, faded, ids = [], 0, {}
    labels = mind.cmap.knowledge.labels
    for k, obj in enumerate(memory.objects):
        label, position = obj["label"], tuple(float(v) for v in obj["position"])
        if label not in labels:
            faded += 1  # a label the knowledge no longer lists
            continue
        weight = mobility.still_there(label, (start - float(obj["seen_at"])) / DAY_S)
        support = ids.get(obj.get("support"))
        if mobility.fixed(label):
            room = mind.room_at(position[:2])
            if weight < KEEP_FURNITURE or room is None:
                faded += 1
                continue
            known = mind.add_object(label, position, support=support,
                                    room=None if support else room)
            mind.seen_at[known.id] = float(obj["seen_at"]) - start
            ids[k] = known.id
            kept.append(known.id)
            continue
        on = memory.objects[obj["support"]]["label"] if obj.get("support") is not None \
            else None
        mind.remembered.append(Sighting(label, position, float(obj["seen_at"]), weight, on))
    for s in memory.sightings:
        weight = mobility.still_there(s["label"], (start - float(s["seen_at"])) / DAY_S)
        if s["label"] in labels:
            mind.remembered.append(Sighting(
                s["label"], tuple(float(v) for v in s["position"]), float(s["seen_at"]),
                weight, s.get("support")))
    faded += sum(1 for s in mind.remembered if s.weight < FORGET_BELOW)
    mind.remembered[:] = [s for s in mind.remembered if s.weight >= FORGET_BELOW]
    return {"tasks": memory.tasks, "places": len(mind.place_map.places),
            "rooms": len(mind.place_map.rooms), "furniture": len(kept),
            "sightings": [s.to_json() for s in mind.remembered], "faded": faded}


def wanted(mind: Mind, labels: Collection[str]) -> list[Sighting]:
    """The sightings of `labels` not checked yet, most likely first."""
    return sorted((s for s in mind.remembered if s.label in labels),
                  key=lambda s: -s.weight)


# ---- files ------------------------------------------------------------------------------------

def load(directory: str | os.PathLike[str]) -> BuildingMemory | None:
    """The memory kept in `directory`, or None when it holds none yet (a first task)."""
    root = Path(directory)
    path = root / MEMORY_FILE
    if not path.exists():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise BuildingMemoryError(f"{path}: not a building memory ({exc})") from None
    if not isinstance(data, Mapping) or data.get("format") != FORMAT:
        found = data.get("format") if isinstance(data, Mapping) else type(data).__name__
        raise BuildingMemoryError(f"{path}: building memory format {found!r}; this version reads "
                           f"format {FORMAT} (forget the building to start afresh)")
    grid_file = data.get("grid")
    if not isinstance(grid_file, str) or not GRID_FILE.fullmatch(grid_file):
        raise BuildingMemoryError(f"{path}: names no grid file (grid-<n>.npz): {grid_file!r}")
    try:
        with np.load(root / grid_file, allow_pickle=False) as arrays:
            logodds = np.asarray(arrays["logodds"], dtype=np.int8)
            origin = tuple(float(v) for v in arrays["origin"])
            resolution = float(arrays["resolution"])
    except (OSError, KeyError, ValueError) as exc:
        raise BuildingMemoryError(
            f"{root / grid_file}: cannot read the kept grid ({exc})") from None
    try:
        return BuildingMemory(
            tasks=int(data["tasks"]), clock=float(data["clock"]), grid_origin=origin,
            grid_logodds=logodds, grid_resolution=resolution,
            place_map=dict(data["place_map"]), evidence=dict(data["evidence"]),
            objects=list(data["objects"]), sightings=list(data["sightings"]),
            saved=str(data.get("saved", "")))
    except (KeyError, TypeError, ValueError) as exc:
        raise BuildingMemoryError(f"{path}: malformed building memory ({type(exc).__name__}: "
                           f"{exc})") from None


def save(memory: BuildingMemory, directory: str | os.PathLike[str]) -> None:
    """Write `memory` to `directory` (created if need be); each file is replaced whole, so
    a task interrupted while saving leaves the memory before it."""
    root = Path(directory)
    root.mkdir(parents=True, exist_ok=True)
    if memory.grid_logodds is None:
        raise BuildingMemoryError("a building memory without a grid cannot be saved")
    grid_file = f"grid-{memory.tasks}.npz"
    data = {"format": FORMAT, "tasks": memory.tasks, "clock": round(memory.clock, 3),
            "saved": memory.saved, "grid": grid_file, "place_map": memory.place_map,
            "evidence": memory.evidence, "objects": memory.objects,
            "sightings": memory.sightings}
    _replace(root / grid_file, lambda f: np.savez_compressed(
        f, logodds=memory.grid_logodds, origin=np.asarray(memory.grid_origin),
        resolution=np.asarray(memory.grid_resolution)))
    _replace(root / MEMORY_FILE, lambda f: f.write(json.dumps(data).encode("utf-8")))
    for old in root.glob("grid-*.npz"):  # the grids no memory.json names any more
        if old.name != grid_file and GRID_FILE.fullmatch(old.name):
            old.unlink(missing_ok=True)


def _replace(path: Path, write) -> None:  # noqa: ANN001 - a callable taking a binary file
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
