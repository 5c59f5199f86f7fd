"""Map snapshots in the episode's trace: what a viewer (the service's task page) draws.

The episode's wiring (`runner.Episode`) subscribes one `MapSnapshots` to its trace; planners,
strategies and maps never call it. From the events it sees it decides when to read the mind:

- at the start and after every completed step (an `action` event with a final status): a
  `map` event (`done`, always right after a step or a plan, stays the trace's last event);
- while the robot drives or looks (a `belief` event with map changes, an `observation`), a
  `map` event at most every `interval_s` simulated seconds;
- after CREATEVIEWCONES: a `cones` event with the cones' poses and probabilities.

A `map` event is compact. It always has the robot's `pose`; the occupancy `grid` (coarsened to
`resolution`, a base64 PNG: grey unknown, white free, black occupied; rows from north to
south), `places`, `placeholders`, `doors`, `rooms` (each room's likeliest categories with their
probabilities), known `objects` and keep-out discs (`blocked`) only when they changed since the
previous `map` event (then in full); the `path` and the `detections` as the points added since
the previous `map` event, when there are any (`path_from`, `detections_from`: the index of the
first one). A reader keeps the last value of each part.
"""

from __future__ import annotations

import base64
import struct
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np

from conceptual_map.metric import CellState

Emit = Callable[..., Any]

MAP = "map"
CONES = "cones"
_LIVE = frozenset({"belief", "observation"})
_GREY = {CellState.UNKNOWN: 128, CellState.FREE: 255, CellState.OCCUPIED: 0}


class MapSnapshots:
    """Reads the mind, the executor's path and cones and the robot's pose; `observe` is the
    trace subscriber. `emit(type, **fields)` adds an event to the same trace."""

    def __init__(self, executor: Any, emit: Emit, resolution: float = 0.1,
                 interval_s: float = 3.0, top_categories: int = 4):
        self.executor = executor
        self.emit = emit
        self.resolution = resolution
        self.interval_s = interval_s
        self.top_categories = top_categories
        self.maps = 0
        self._last_t: float | None = None
        self._grid_key: tuple[Any, ...] | None = None
        self._grid_version: tuple[Any, ...] | None = None
        self._path_sent = 0
        self._detections_sent = 0
        self._busy = False
        self._sent: dict[str, Any] = {}
        self._cone_sets: dict[tuple[str, str, str], Any] = {}  # the ConeSets already sent

    # ---- when ------------------------------------------------------------------------------

    def observe(self, event: dict[str, Any]) -> None:
        """The trace's subscriber: may emit a `cones` and/or a `map` event after `event`."""
        kind = event.get("type")
        if self._busy or kind in (MAP, CONES):
            return
        self._busy = True  # the events emitted here come back through the trace
        try:
            if kind == "action" and event.get("action") == "createviewcones":
                self._cones()
            if self._due(event):
                self.snapshot()
        finally:
            self._busy = False

    def _due(self, event: dict[str, Any]) -> bool:
        kind = event.get("type")
        if kind == "start":
            return True
        if kind == "action":
            return event.get("status") not in (None, "start")
        if kind in _LIVE:
            t = float(event.get("t", 0.0))
            return self._last_t is None or t - self._last_t >= self.interval_s
        return False

    # ---- what ------------------------------------------------------------------------------

    def snapshot(self) -> None:
        """Emit one `map` event with the mind's current state."""
        ex = self.executor
        mind = ex.mind
        pm = mind.place_map
        x, y, yaw = ex.robot.pose
        fields: dict[str, Any] = {"pose": [_r(x), _r(y), round(float(yaw), 3)]}
        grid = self._grid()
        if grid is not None:
            fields["grid"] = grid
        parts = {
            "places": [[pid, _r(p.position[0]), _r(p.position[1]), pm.room_of(pid)]
                       for pid, p in pm.places.items()],
            "placeholders": [[pid, _r(p.position[0]), _r(p.position[1])]
                             for pid, p in pm.placeholders.items()],
            "doors": [[did, *(_r(v) for v in (*d.ends[0], *d.ends[1]))]
                      for did, d in pm.doors.items()],
            "rooms": self._rooms(),
            "objects": [[o.id, o.label, _r(o.position[0]), _r(o.position[1]), o.room]
                        for o in mind.objects.values()],
            "blocked": [[_r(bx), _r(by), _r(br)] for bx, by, br in mind.grid.keep_out],
        }
        for name, value in parts.items():  # unchanged parts are left out
            if self._sent.get(name) != value:
                fields[name] = self._sent[name] = value
        path, seen = ex.stats.path, ex.stats.detections
        if len(path) > self._path_sent:  # left out when no point was added
            fields["path_from"] = self._path_sent
            fields["path"] = [[_r(p[0]), _r(p[1])] for p in path[self._path_sent:]]
            self._path_sent = len(path)
        if len(seen) > self._detections_sent:
            fields["detections_from"] = self._detections_sent
            fields["detections"] = [[_r(d[0]), _r(d[1]), d[2], bool(d[3])]
                                    for d in seen[self._detections_sent:]]
            self._detections_sent = len(seen)
        self._last_t = float(ex.robot.clock)
        self.maps += 1
        self.emit(MAP, **fields)

    def _rooms(self) -> dict[str, dict[str, float]]:
        """Each room's most likely categories (descending) with their probabilities."""
        mind = self.executor.mind
        out: dict[str, dict[str, float]] = {}
        for rid in mind.place_map.rooms:
            if not mind.cmap.graph.has_room(rid):
                continue
            belief = sorted(mind.cmap.room_category(rid).items(), key=lambda kv: -kv[1])
            out[rid] = {c: round(float(p), 3) for c, p in belief[:self.top_categories]
                        if p >= 0.005}
        return out

    def _grid(self) -> dict[str, Any] | None:
        """The coarse grid as a PNG, or None when it looks as in the last `map` event."""
        grid = self.executor.mind.grid
        version = (grid.version, tuple(np.round(grid.origin, 6)), grid.shape)
        if version == self._grid_version:
            return None
        self._grid_version = version
        k = max(1, round(self.resolution / grid.resolution))
        coarse = coarsen(grid.state_grid(), k)
        key = (version[1], coarse.shape, zlib.crc32(coarse.tobytes()))
        if key == self._grid_key:
            return None
        self._grid_key = key
        grey = np.full(coarse.shape, _GREY[CellState.UNKNOWN], dtype=np.uint8)
        grey[coarse == CellState.FREE] = _GREY[CellState.FREE]
        grey[coarse == CellState.OCCUPIED] = _GREY[CellState.OCCUPIED]
        image = grey.T[::-1]  # rows: y from the top (north) down; columns: x
        return {"origin": [_r(v) for v in grid.origin], "resolution": grid.resolution * k,
                "size": [int(coarse.shape[0]), int(coarse.shape[1])],
                "png": base64.b64encode(png_grey(image)).decode("ascii")}

    def _cones(self) -> None:
        """The cones of the CREATEVIEWCONES just executed, as [x, y, yaw, probability]."""
        ex = self.executor
        fresh = [(key, made) for key, made in ex.cones.items()
                 if self._cone_sets.get(key) is not made]
        self._cone_sets = dict(ex.cones)
        if not fresh:
            return
        (label, relation, location), made = fresh[-1]
        cam = ex.camera
        self.emit(CONES, label=label, relation=relation, location=location,
                  coverage=round(made.coverage, 3), fov=round(cam.hfov, 4),
                  range=round(cam.detect_range, 2),
                  cones=[[_r(c.pose[0]), _r(c.pose[1]), round(float(c.pose[2]), 3),
                          round(float(c.probability), 4)] for c in made.cones])


def coarsen(states: np.ndarray, k: int) -> np.ndarray:
    """Blocks of k x k cells: occupied if any cell is, else free if any is, else unknown (a
    wall one fine cell thick stays a wall): the largest CellState of the block."""
    assert CellState.UNKNOWN < CellState.FREE < CellState.OCCUPIED
    if k == 1:
        return states.astype(np.uint8)
    w, h = states.shape
    padded = np.pad(states.astype(np.uint8), ((0, -w % k), (0, -h % k)),
                    constant_values=CellState.UNKNOWN)
    out = padded[0::k, 0::k].copy()
    for i in range(k):
        for j in range(k):
            if i or j:
                np.maximum(out, padded[i::k, j::k], out=out)
    return out


def png_grey(image: np.ndarray) -> bytes:
    """An 8-bit greyscale PNG of a 2D uint8 array (row 0 at the top)."""
    height, width = image.shape
    raw = np.zeros((height, width + 1), dtype=np.uint8)  # filter byte 0 before each row
    raw[:, 1:] = image
    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", header)
            + _chunk(b"IDAT", zlib.compress(raw.tobytes(), 9)) + _chunk(b"IEND", b""))


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def _r(value: float) -> float:
    return round(float(value), 2)
