"""`Recorder`: an episode as a Rerun recording, on the simulated-time timeline `sim_time`.

It subscribes to the trace (`Trace.subscribe`) and, at each event, reads what changed in the
robot's mind: the occupancy grid (as it grows, at most every `grid_every_s` simulated
seconds), the voxel map where there is one, places, placeholders, doors and rooms with their
believed category and P(target), the robot's path and pose, the view cones of the last
CREATEVIEWCONES with the DT's belief over them while a search runs, detections, and the current
plan as text with its assumptive steps marked. Nothing here changes the episode: beliefs are
read only when the conceptual map is up to date (reading them otherwise would run its
inference early), and the grid's derived arrays are the ones the planners cache anyway.

Entity paths (the tests check them): `world/grid`, `world/voxels`, `world/places`,
`world/placeholders`, `world/doors`, `world/rooms`, `world/robot/path`, `world/robot/pose`,
`world/cones`, `world/detections`, `plan`, `plan/probability`, `dt/belief`, `log`.
"""

from __future__ import annotations

import colorsys
import hashlib
import logging
import math
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from avs_planner.viewer.errors import ViewerError, display_missing, require_rerun

log = logging.getLogger(__name__)

TIMELINE = "sim_time"
_KNOWN = {  # category -> RGB, others get a stable colour from their name
    "corridor": (150, 150, 150), "office": (66, 135, 245), "kitchen": (240, 160, 40),
    "meeting_room": (150, 90, 200), "living_room": (80, 180, 90), "bathroom": (60, 200, 200),
    "bedroom": (230, 90, 120), "lab": (200, 200, 60),
}
_UNKNOWN_CELL, _FREE_CELL, _OCCUPIED_CELL = 255, 0, 100  # nav_msgs/OccupancyGrid values


def category_colour(category: str | None) -> tuple[int, int, int]:
    if not category:
        return (200, 200, 200)
    if category in _KNOWN:
        return _KNOWN[category]
    hue = int(hashlib.md5(category.encode()).hexdigest()[:4], 16) / 0xFFFF
    r, g, b = colorsys.hsv_to_rgb(hue, 0.6, 0.9)
    return (int(r * 255), int(g * 255), int(b * 255))


class Recorder:
    """Logs an episode to `path` (an .rrd file) and/or a live viewer (`spawn`)."""

    def __init__(self, mind: Any, executor: Any, robot: Any, camera: Any, target: str,
                 path: Path | None = None, spawn: bool = False, grid_every_s: float = 2.0,
                 voxels_every_s: float = 10.0, name: str = "episode"):
        if path is None and not spawn:
            raise ViewerError("a recorder needs a file to write or a viewer to stream to")
        started = time.perf_counter()
        rr = require_rerun()
        self.rr = rr
        self.mind, self.executor, self.robot, self.camera = mind, executor, robot, camera
        self.target = target
        self.grid_every_s, self.voxels_every_s = grid_every_s, voxels_every_s
        self.rec = rr.RecordingStream("avs-planner", recording_id=name)
        sinks = []
        if spawn:
            missing = display_missing()
            if missing:
                raise ViewerError(f"cannot open a live Rerun viewer: {missing}; record the "
                                  f"episode with --record instead and replay it with `avs view "
                                  f"RUN_DIR --web` (a browser) or where a display is available")
            try:
                rr.spawn(connect=False, hide_welcome_screen=True)
            except Exception as exc:  # noqa: BLE001 - no display, no viewer binary
                raise ViewerError(f"cannot start the Rerun viewer ({exc}); record to a file "
                                  f"with --record and open it with `avs view` where a display "
                                  f"is available") from None
            sinks.append(rr.GrpcSink())
        if path is not None:
            sinks.append(rr.FileSink(str(path)))
        self.rec.set_sinks(*sinks)
        self.path = path
        self.rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        self._grid_version: int | None = None
        self._grid_t = -math.inf
        self._voxels_t = -math.inf
        self._voxel_count = -1
        self._map_key: tuple | None = None
        self._beliefs: dict[str, tuple[str, float, float | None]] = {}  # room -> cat, p, P(t)
        self._path_len = 0
        self._pose: tuple[float, ...] | None = None
        self._cones: Any = None
        self._session: Any = None
        self._belief_key: Any = None
        self._detections: list[tuple[list[float], bool]] = []
        self._t = 0.0
        self.events = 0
        self.closed = False
        self.cost_s = time.perf_counter() - started  # wall time spent recording (bench)

    # ---- the trace's listener ---------------------------------------------------------------

    def __call__(self, event: Mapping[str, Any]) -> None:
        if self.closed:
            return
        started = time.perf_counter()
        try:
            self._record(event)
        finally:
            self.cost_s += time.perf_counter() - started
        if event.get("type") == "done":
            self.close()

    def _record(self, event: Mapping[str, Any]) -> None:
        self.events += 1
        self._t = float(event.get("t") or 0.0)
        self.rec.set_time(TIMELINE, duration=self._t)
        kind = event.get("type")
        self._robot()
        self._grid(force=kind in ("start", "done"))
        self._voxels(force=kind == "done")
        self._place_map(force=kind in ("plan", "done"))
        if kind == "plan":
            self._plan(event)
        elif kind in ("replan", "done", "warning") or (kind == "action" and
                                                        event.get("status") != "start"):
            self._log(event)
        elif kind == "observation" and isinstance(event.get("position"), list):
            self._detection(event)
        elif kind == "belief" and ("blocked" in event or "cut_off" in event
                                   or "doubt_categories" in event):
            self._log(event)
        self._view_cones()

    def close(self) -> None:
        """Flush the recording (the file is complete and readable afterwards)."""
        if self.closed:
            return
        started = time.perf_counter()
        self.closed = True
        try:
            self.rec.flush()
            self.rec.disconnect()
        except Exception as exc:  # noqa: BLE001 - a viewer that went away must not fail the run
            log.warning("the Rerun recording could not be completed: %s", exc)
        self.cost_s += time.perf_counter() - started

    # ---- what is logged ---------------------------------------------------------------------

    def _robot(self) -> None:
        rr = self.rr
        pose = tuple(float(v) for v in self.robot.pose)
        if pose != self._pose:
            x, y, yaw = pose
            self._pose = pose
            self.rec.log("world/robot/pose", rr.Arrows3D(
                origins=[[x, y, 0.1]], vectors=[[0.6 * math.cos(yaw), 0.6 * math.sin(yaw), 0.0]],
                colors=[(20, 20, 20)], radii=0.04, labels=["robot"]))
        path = self.executor.stats.path
        if len(path) != self._path_len and len(path) >= 2:
            self._path_len = len(path)
            self.rec.log("world/robot/path", rr.LineStrips3D(
                [[(p[0], p[1], 0.05) for p in path]], colors=[(230, 60, 60)], radii=0.03))

    def _grid(self, force: bool = False) -> None:
        grid = self.mind.grid
        if grid.version == self._grid_version:
            return
        if not force and self._t - self._grid_t < self.grid_every_s:
            return
        self._grid_version, self._grid_t = grid.version, self._t
        states = grid.state_grid()
        image = np.full(states.shape, _UNKNOWN_CELL, dtype=np.uint8)
        image[states == 1] = _FREE_CELL
        image[states == 2] = _OCCUPIED_CELL
        image = np.ascontiguousarray(image.T)  # rows along y, from the origin (ROS order)
        height, width = image.shape
        rr = self.rr
        self.rec.log("world/grid", rr.GridMap(
            data=image.tobytes(),
            format=rr.components.ImageFormat(width=width, height=height, color_model="L",
                                             channel_datatype="U8"),
            cell_size=grid.resolution,
            translation=[float(grid.origin[0]), float(grid.origin[1]), 0.0],
            colormap=rr.components.Colormap.RvizMap))

    def _voxels(self, force: bool = False) -> None:
        voxels = getattr(self.mind, "voxels", None)
        if voxels is None or (not force and self._t - self._voxels_t < self.voxels_every_s):
            return
        flat = np.flatnonzero(voxels.logodds.ravel() >= voxels.model.occupied_at)
        if len(flat) == self._voxel_count:
            return
        self._voxels_t, self._voxel_count = self._t, len(flat)
        points = voxels.to_world(np.stack(np.unravel_index(flat, voxels.shape), axis=1))
        points = points.astype(np.float32)
        colours = _height_colours(points[:, 2])
        self.rec.log("world/voxels", self.rr.Points3D(points, colors=colours,
                                                      radii=voxels.resolution / 2))

    def _room_beliefs(self) -> dict[str, tuple[str, float, float | None]]:
        """Room -> (most likely category, its probability, P(target in room)), read only when
        the conceptual map is up to date (else the last ones read)."""
        cmap = self.mind.cmap
        if getattr(cmap, "_dirty", True) or getattr(cmap, "last_result", None) is None:
            return self._beliefs
        out: dict[str, tuple[str, float, float | None]] = {}
        for rid in self.mind.place_map.rooms:
            if not cmap.graph.has_room(rid):
                continue
            belief = cmap.room_category(rid)
            best = max(belief, key=belief.get)
            try:
                p_target = float(cmap.p_object_at(self.target, rid))
            except Exception:  # noqa: BLE001 - a label the knowledge base does not know
                p_target = None
            out[rid] = (best, float(belief[best]), p_target)
        self._beliefs = out
        return out

    def _place_map(self, force: bool = False) -> None:
        pm = self.mind.place_map
        beliefs = self._room_beliefs()
        key = (len(pm.places), len(pm.placeholders), len(pm.doors),
               tuple(sorted((r, tuple(sorted(room.places))) for r, room in pm.rooms.items())),
               tuple(sorted((r, b[0], round(b[1], 3), None if b[2] is None else round(b[2], 3))
                            for r, b in beliefs.items())),
               tuple(sorted(pm.placeholders)))
        if key == self._map_key:
            return
        self._map_key = key
        rr = self.rr
        room_of = {pid: rid for rid, room in pm.rooms.items() for pid in room.places}
        if pm.places:
            ids = sorted(pm.places)
            pos = [(*pm.places[p].position[:2], 0.15) for p in ids]
            colours = [category_colour((beliefs.get(room_of.get(p, "")) or ("",))[0])
                       for p in ids]
            self.rec.log("world/places", rr.Points3D(pos, colors=colours, radii=0.12,
                                                     labels=ids, show_labels=False))
        if pm.placeholders:
            ids = sorted(pm.placeholders)
            pos = [(*pm.placeholders[p].position[:2], 0.15) for p in ids]
            self.rec.log("world/placeholders", rr.Points3D(
                pos, colors=[(255, 210, 0)] * len(ids), radii=0.1, labels=ids,
                show_labels=False))
        else:
            self.rec.log("world/placeholders", rr.Clear(recursive=False))
        if pm.doors:
            ids = sorted(pm.doors)
            strips = [[(*pm.doors[d].ends[0][:2], 0.3), (*pm.doors[d].ends[1][:2], 0.3)]
                      for d in ids]
            self.rec.log("world/doors", rr.LineStrips3D(strips, colors=[(120, 70, 30)],
                                                        radii=0.06, labels=ids))
        rooms = [r for r in sorted(pm.rooms) if pm.rooms[r].places & set(pm.places)]
        if rooms:
            centres, labels, colours = [], [], []
            for rid in rooms:
                xy = np.mean([pm.places[p].position[:2] for p in pm.rooms[rid].places
                              if p in pm.places], axis=0)
                centres.append((float(xy[0]), float(xy[1]), 0.6))
                belief = beliefs.get(rid)
                if belief is None:
                    labels.append(rid)
                    colours.append(category_colour(None))
                else:
                    p_t = "" if belief[2] is None else f", P({self.target})={belief[2]:.2f}"
                    labels.append(f"{rid}: {belief[0]} {belief[1]:.2f}{p_t}")
                    colours.append(category_colour(belief[0]))
            self.rec.log("world/rooms", rr.Points3D(centres, colors=colours, radii=0.2,
                                                    labels=labels))

    def _plan(self, event: Mapping[str, Any]) -> None:
        steps = event.get("plan") or []
        probs = event.get("step_p") or []
        assumptive = set(event.get("assumptive") or [i for i, s in enumerate(steps)
                                                     if s.startswith("(assume-")])
        lines = [f"### Plan ({event.get('why')}): {event.get('status')}, "
                 f"p = {event.get('probability', 0.0)}", ""]
        for i, step in enumerate(steps):
            p = f" — p {probs[i]:.3g}" if i < len(probs) else ""
            mark = "**[assume]** " if i in assumptive else ""
            lines.append(f"{i + 1}. {mark}`{step}`{p}")
        if not steps:
            lines.append("(no plan)")
        rr = self.rr
        self.rec.log("plan", rr.TextDocument("\n".join(lines), media_type="text/markdown"))
        if event.get("probability") is not None:
            self.rec.log("plan/probability", rr.Scalars([float(event["probability"])]))
        self._log(event)

    def _log(self, event: Mapping[str, Any]) -> None:
        kind = event.get("type")
        if kind == "plan":
            text = f"plan ({event.get('why')}): {event.get('status')}"
        elif kind == "replan":
            text = (f"replan: {event.get('status')} {event.get('action')} "
                    f"{event.get('detail') or ''}")
        elif kind == "done":
            text = f"done: {event.get('outcome')}: {event.get('reason')}"
        elif kind == "action":
            detail = event.get("detail") or ""
            text = f"{event.get('action')} {event.get('status')}" + (f": {detail}" if detail
                                                                     else "")
        else:
            text = f"{kind}: " + ", ".join(f"{k}={v}" for k, v in event.items()
                                           if k not in ("t", "wall", "type"))
        level = "WARN" if kind in ("replan", "warning") else "INFO"
        self.rec.log("log", self.rr.TextLog(text, level=level))

    def _detection(self, event: Mapping[str, Any]) -> None:
        pos = [float(v) for v in event["position"]] + [0.0] * (3 - len(event["position"]))
        self._detections.append((pos[:3], bool(event.get("detected"))))
        self.rec.log("world/detections", self.rr.Points3D(
            [d[0] for d in self._detections],
            colors=[(30, 200, 60) if ok else (220, 30, 30) for _, ok in self._detections],
            radii=0.08, labels=[f"{event.get('label')} {'confirmed' if ok else 'not confirmed'}"
                                for _, ok in self._detections], show_labels=False))

    def _view_cones(self) -> None:
        """The last CREATEVIEWCONES' cones, shaded by P(target in cone): the DT's belief while
        its search runs over them (the cone at the robot's pose is the one being processed),
        else the cones' own prior."""
        cones = self.executor.cones
        latest = next(reversed(cones.values())) if cones else None
        if latest is None or not latest.cones:
            return
        cone_list = list(latest.cones)
        session = getattr(self.executor, "dt_session", None)
        live = (session is not None and getattr(session, "problem", None) is not None
                and [c.id for c in session.problem.cones] == [c.id for c in cone_list])
        belief = session.belief if live else None
        current = None
        if live and not session.finished:
            x, y = self.robot.pose[:2]
            near = [(math.dist((x, y), c.pose[:2]), i) for i, c in enumerate(cone_list)]
            d, i = min(near)
            current = i if d < 0.3 else None
        key = (id(latest), id(belief), current)
        if key == self._belief_key:
            return
        self._belief_key = key
        probs = list(belief.probs[:-1]) if belief is not None else [c.probability
                                                                     for c in cone_list]
        top = max(probs) or 1.0
        strips, colours, labels, radii = [], [], [], []
        half, reach = self.camera.hfov / 2, self.camera.detect_range
        for i, (cone, p) in enumerate(zip(cone_list, probs, strict=True)):
            x, y, yaw = cone.pose[:3]
            yaw += (cone.head or (0.0, 0.0))[0]
            left = (x + reach * math.cos(yaw + half), y + reach * math.sin(yaw + half), 0.2)
            right = (x + reach * math.cos(yaw - half), y + reach * math.sin(yaw - half), 0.2)
            strips.append([(x, y, 0.2), left, right, (x, y, 0.2)])
            shade = int(60 + 195 * p / top)
            colours.append((255, 230, 0) if i == current else (shade, 40, 255 - shade))
            radii.append(0.05 if i == current else 0.02)
            labels.append(f"{cone.id}: p={p:.2f}" + (" (processing)" if i == current else ""))
        self.rec.log("world/cones", self.rr.LineStrips3D(strips, colors=colours, radii=radii,
                                                         labels=labels))
        if belief is not None:
            self.rec.log("dt/belief", self.rr.BarChart(np.asarray(belief.probs, dtype=float)))


def _height_colours(z: np.ndarray) -> np.ndarray:
    span = float(z.max() - z.min()) if len(z) else 1.0
    t = (z - (z.min() if len(z) else 0.0)) / (span or 1.0)
    return np.stack([60 + 180 * t, 120 + 60 * (1 - t), 220 - 160 * t], axis=1).astype(np.uint8)
