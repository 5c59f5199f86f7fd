"""Frames taken in passing are evidence too: where they did not show the target, it is less
likely to be.

While driving, the detector looks ahead for the target, and at a new place the robot looks
both ways (`Executor.watch`, `Executor.look_around`). Until now a frame that showed nothing
was dropped: only the DT's searches lowered P(ObjectAt), so a room the robot had looked
across on its way was searched from scratch, and on an absent target the budget ran out
before the building's hypotheses did. Here every such frame counts:

- **Rooms.** The cells a room search would cover (`viewcones.candidate_cells`: occupied or
  unknown cells bordering the room's free floor, all of it) count as looked at
  when a frame had them in view: inside the camera's horizontal field of view, between 0.5 m
  and 0.9 x the recognition range (the room cones' own limits), an object at the assumed
  support height inside the vertical field of view, and a free line of sight on the
  occupancy grid (an unknown or occupied cell in between blocks it).
- **Supports.** The top of a known support (at twice its detected centre's height, the
  executor's rule for a top) is the disc within `support_radius` of its centre, where the
  executor calls a detection "on" it, sampled by points spread evenly over it. A point
  counts as looked at when it is inside the field of view and the range, and the centre has
  a free line of sight that may end in the support's own body (the laser maps a desk as its
  outline with unknown cells inside, which a ray to its centre crosses; without this, no top
  in view ever counted). Like a room's cells, a top seen in part is searched in part: the
  share is the mean over its points (an object at the desk's far end is not ruled out by
  frames that only had its near end in view, and a desk seen whole from one standpoint is
  not needed whole in every frame).

A look is one chance for the detector (hit rate `p_detect`, the DT's own detector model), so
a cell or top looked at from k different standpoints (camera positions 1 m apart; frames
from the same standpoint see the same thing and count once) would have missed an object
with probability (1 - p_detect)^k, and Poisson thinning leaves the mean of that over a
room's cells (or the top's own value) of the label's count unseen. That share goes to the
conceptual map as glimpses (`ConceptualMap.observe_glimpses`, replacing the last share
given). The planner then sees the lowered P(ObjectAt) in its `p-obj-in` values, and a
support whose P(target on it) falls below the planner's threshold is settled
(`StateBuilder`). The DT's own searches are recorded apart (`Mind.searched`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np

from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.viewcones import CameraModel, candidate_cells
from conceptual_map.conceptual import RelatedSpace
from conceptual_map.metric import CellState

STANDPOINT = 1.0  # m: camera positions nearer than this are one standpoint
# frames kept to credit to a support's top once it is known: a look round's dozen and more
RECENT_FRAMES = 32
MAX_LOOKS = 4  # standpoints counted per cell (beyond, a miss is practically ruled out)


class Glimpses:
    """What frames taken in passing have seen of rooms and supports, per label."""

    def __init__(self, mind: Mind, camera: CameraModel, p_detect: float,
                 min_range: float = 0.5, support_body: float = 0.9) -> None:
        self.mind, self.camera, self.p_detect = mind, camera, p_detect
        self.min_range = min_range
        # m from a support's centre that may be its own body on the way to its top (the
        # executor's `support_radius`: a detection this near a support is on it)
        self.support_body = support_body
        self.max_range = 0.9 * camera.detect_range
        # label -> {world key of a candidate cell: standpoints it was looked at from}
        self.cells: dict[str, dict[tuple[int, int], set[tuple[int, int]]]] = {}
        # (label, support id) -> per point of its top (`_top_points`), the standpoints it
        # was looked at from
        self.tops: dict[tuple[str, str], list[set[tuple[int, int]]]] = {}
        self._top_points = _disc_points(support_body)
        self.frames = 0
        # the last frames checked for a label on tops (pose, pan, tilt, standpoint), and the
        # supports whose top they were credited to (`_tops`)
        self._recent: dict[str, list[tuple[tuple[float, float, float], float, float,
                                           tuple[int, int]]]] = {}
        self._credited: set[tuple[str, str]] = set()

    def frame(self, pose: tuple[float, float, float], pan: float, tilt: float,
              labels: Iterable[str], supports: Iterable[str] = (),
              tops_label: str | None = None,
              shown: Mapping[str, Sequence[Sequence[float]]] | None = None
              ) -> dict[str, dict[str, float]]:
        """A frame from `pose` with the head at (`pan`, `tilt`) did not show `labels`; the
        tops of the known objects `supports` are checked for `tops_label` (the target).
        `shown`: labels the frame did show, with where (x, y): it did not show another one
        anywhere else it had in view, so the cells farther than `support_body` from those
        detections count as looked at for them too (else a room whose known desk was in
        every frame kept its prior count of desks not found yet, wherever the frames
        looked). Returns, per label, the rooms whose share changed and the new share."""
        labels = list(labels)
        shown = {lab: where for lab, where in (shown or {}).items() if lab not in labels}
        self.frames += 1
        stand = _standpoint(pose)
        changed: dict[str, dict[str, float]] = {}
        points, rooms = (candidate_cells(self.mind) if labels or shown
                         else (np.zeros((0, 2)), np.zeros(0, dtype=object)))
        if len(points):
            seen = self.in_view(points, pose, pan, tilt, self.camera.support_height)
            keys = [tuple(k) for k in self._keys(points).tolist()]
            masks = [(label, seen) for label in labels]
            for label, where in shown.items():
                near = np.zeros(len(points), dtype=bool)
                for xy in where:
                    near |= np.hypot(*(points - np.asarray(xy[:2])).T) <= self.support_body
                masks.append((label, seen & ~near))
            for label, mask in masks:
                looks = self.cells.setdefault(label, {})
                new = False
                for i in np.flatnonzero(mask):
                    where = looks.setdefault(keys[i], set())
                    if stand not in where and len(where) < MAX_LOOKS:
                        where.add(stand)
                        new = True
                if not new:
                    continue
                for room in {r for r in rooms[mask] if r is not None}:
                    mine = [keys[i] for i in np.flatnonzero(rooms == room)]
                    share = self._share([len(looks.get(k, ())) for k in mine])
                    self._observe(label, room, share)
                    changed.setdefault(label, {})[room] = round(share, 3)
        if tops_label is not None:
            self._tops(pose, pan, tilt, tops_label, supports, stand,
                       missed=tops_label in labels)
        return changed

    def frame_value(self, pose: tuple[float, float, float], pan: float, tilt: float,
                    labels: Sequence[str], p_room: Callable[[str, str], float]) -> float:
        """P(a frame from `pose`, the head at (`pan`, `tilt`), shows one of `labels`), as
        the looks so far leave it: for each label and each room with candidate cells in
        view, the room's P(label there) (`p_room(label, room)`, already thinned by these
        looks) times the share of its unseen mass in view that this standpoint has not
        looked at yet (a cell weighs (1 - p_detect) to the number of standpoints it was
        looked at from, as `_share` counts it), times p_detect. Infinite when the frame
        would see space outside the rooms the robot has entered (unknown cells, or free
        floor no such room holds: a room beyond a door), which the map cannot price."""
        if self._sees_beyond(pose, pan):
            return math.inf
        points, rooms = candidate_cells(self.mind)
        if not len(points):
            return math.inf
        seen = self.in_view(points, pose, pan, tilt, self.camera.support_height)
        if not seen.any():
            return 0.0
        keys = [tuple(k) for k in self._keys(points).tolist()]
        stand = _standpoint(pose)
        miss = 1.0 - self.p_detect
        value = 0.0
        for label in labels:
            looks = self.cells.get(label, {})
            counts = [looks.get(k, ()) for k in keys]
            weight = np.array([miss ** len(c) for c in counts])
            # a cell looked at from this standpoint already, or as often as `frame` counts,
            # is no new chance (the same rule `frame` keeps)
            fresh = seen & np.array([stand not in c and len(c) < MAX_LOOKS for c in counts],
                                    dtype=bool)
            for room in {r for r in rooms[fresh] if r is not None}:
                mine = rooms == room
                total = float(weight[mine].sum())
                if total > 0.0:
                    value += (self.p_detect * p_room(label, room)
                              * float(weight[mine & fresh].sum()) / total)
        return value

    def _sees_beyond(self, pose: tuple[float, float, float], pan: float) -> bool:
        """Whether a frame from `pose` would see, along a free line of sight, a cell that is
        unknown or free floor no entered room holds (sampled over the field of view and the
        counted range)."""
        grid = self.mind.grid
        owner, _ = self.mind.place_map.room_extents(grid)
        cam = self.camera
        angles = pose[2] + pan + np.linspace(-cam.hfov / 2, cam.hfov / 2, 9)
        ranges = np.arange(self.min_range, self.max_range + 1e-9, 2.0 * grid.resolution)
        points = (np.asarray(pose[:2])[None, None, :] + ranges[:, None, None]
                  * np.stack([np.cos(angles), np.sin(angles)], axis=1)[None, :, :])
        points = points.reshape(-1, 2)
        points = points[self.line_of_sight(np.asarray(pose[:2]), points)]
        if not len(points):
            return False
        cells = grid.to_cell(points)
        inside = grid.inside(cells)
        if not inside.all():
            return True
        where = tuple(cells.T)
        state = grid.state_grid()[where]
        return bool(np.any((state == CellState.UNKNOWN)
                           | ((state == CellState.FREE) & (owner[where] == 0))))

    def _share(self, looks: list[int]) -> float:
        """Share of a location's objects the looks would have seen: 1 - mean miss."""
        if not looks:
            return 0.0
        miss = (1.0 - self.p_detect) ** np.asarray(looks, dtype=float)
        return float(1.0 - miss.mean())

    def _observe(self, label: str, location: str | RelatedSpace, share: float) -> None:
        cmap = self.mind.cmap
        if isinstance(location, str) and not cmap.graph.has_room(location):
            return
        cmap.observe_glimpses(label, location, min(1.0, share))

    def _tops(self, pose: tuple[float, float, float], pan: float, tilt: float, label: str,
              supports: Iterable[str], stand: tuple[int, int], missed: bool = True) -> None:
        """Each known support's top points this frame had in view, looked at once more from
        `stand`. A support checked here for the first time is first credited with the
        frames before this one (the last `RECENT_FRAMES`): the frames that found and
        confirmed it had its top in view too, without the target on it, before it was a
        known object; counted only from then on, a desk the first look round found kept
        its whole prior share, and the CP planned a search of it as if nobody had looked.
        `missed`: the frame did not show `label` (only such frames are kept for later)."""
        recent = self._recent.setdefault(label, [])
        for oid in supports:
            obj = self.mind.objects.get(oid)
            if obj is None:
                continue
            frames = [(pose, pan, tilt, stand)]
            if (label, oid) not in self._credited:
                self._credited.add((label, oid))
                frames = [*recent, *frames]
            new = False
            for f_pose, f_pan, f_tilt, f_stand in frames:
                seen = self._top_in_view(obj.position[:2], f_pose, f_pan, f_tilt, _top(obj))
                if not seen.any():
                    continue
                looks = self.tops.setdefault((label, oid), [set() for _ in self._top_points])
                for i in np.flatnonzero(seen):
                    if f_stand not in looks[i] and len(looks[i]) < MAX_LOOKS:
                        looks[i].add(f_stand)
                        new = True
            if new:
                looks = self.tops[(label, oid)]
                self._observe(label, RelatedSpace("on", oid),
                              self._share([len(where) for where in looks]))
        if missed:
            recent.append((pose, pan, tilt, stand))
            del recent[:-RECENT_FRAMES]

    def top_share(self, oid: str, looks: Iterable[tuple[tuple[float, float, float], float,
                                                       float, int]]) -> float | None:
        """The share of the known object `oid`'s top that `looks` would have seen: each look
        (camera pose, pan, tilt, how many times) is one chance for the detector at every point
        of the top it had in view (`_top_in_view`). A DT search of a support looks at it
        from several standpoints around it, each seeing most of the top: those are repeated
        chances at the same objects, not a partition of them. None for an unknown object."""
        obj = self.mind.objects.get(oid)
        if obj is None:
            return None
        counts = np.zeros(len(self._top_points))
        for pose, pan, tilt, times in looks:
            counts += times * self._top_in_view(obj.position[:2], pose, pan, tilt, _top(obj))
        return self._share(counts.tolist())

    def _top_in_view(self, centre: tuple[float, float], pose: tuple[float, float, float],
                     pan: float, tilt: float, top: float) -> np.ndarray:
        """Which points of the top (`_top_points` around `centre`, at height `top`) are in
        the frame (`in_frame`); none unless the centre has a free line of sight up to the
        support's own body."""
        points = np.asarray(centre, dtype=float) + self._top_points
        seen = self.in_frame(points, pose, pan, tilt, top)
        if seen.any():
            point = np.array([centre], dtype=float)
            if not self.line_of_sight(np.asarray(pose[:2]), point, self.support_body)[0]:
                seen[:] = False
        return seen

    def _keys(self, points: np.ndarray) -> np.ndarray:
        return np.round(points / self.mind.grid.resolution).astype(np.int64)

    def in_frame(self, points: np.ndarray, pose: tuple[float, float, float], pan: float,
                 tilt: float, height: float | np.ndarray) -> np.ndarray:
        """Points (at `height`, one for all or one each) inside the frame: within the
        horizontal and vertical fields of view and between `min_range` and `max_range` (no
        line of sight tested)."""
        cam = self.camera
        d = points - np.asarray(pose[:2])
        r = np.hypot(d[:, 0], d[:, 1])
        yaw = pose[2] + pan
        bearing = np.abs((np.arctan2(d[:, 1], d[:, 0]) - yaw + np.pi) % (2 * np.pi) - np.pi)
        ok = (r >= self.min_range) & (r <= self.max_range) & (bearing <= cam.hfov / 2)
        if cam.vfov is not None:
            elevation = np.arctan2(height - cam.height, np.maximum(r, 1e-6))
            ok &= np.abs(elevation - tilt) <= cam.vfov / 2
        return ok

    def in_view(self, points: np.ndarray, pose: tuple[float, float, float], pan: float,
                 tilt: float, height: float) -> np.ndarray:
        """Points (at `height`) inside the frame (`in_frame`) with a free line of sight."""
        ok = self.in_frame(points, pose, pan, tilt, height)
        if not ok.any():
            return ok
        idx = np.flatnonzero(ok)
        ok[idx] = self.line_of_sight(np.asarray(pose[:2]), points[idx])
        return ok

    def line_of_sight(self, origin: np.ndarray, points: np.ndarray, body: float = 0.0
                       ) -> np.ndarray:
        """True where every grid cell between `origin` and the point is known free, leaving
        out the robot's own footprint (its laser never sees the cells under it) and the last
        cell and a half (the point's own cell holds the object). With `body` > 0 the point
        is the centre of a support whose top is looked at: the ray may end in the support's
        own body (its occupied outline, the unknown inside it), one run of cells that are
        not free within `body` m of the centre with no free cell after it; before that run
        every cell must be free."""
        grid = self.mind.grid
        res = grid.resolution
        free = grid.state_grid() == CellState.FREE
        d = points - origin
        length = np.hypot(d[:, 0], d[:, 1])
        steps = np.maximum(1, np.ceil(length / (0.5 * res)).astype(int))
        n = int(steps.max())
        t = np.arange(n)[None, :] / steps[:, None]  # fraction along each ray
        along = t * length[:, None]
        inside_ray = (along <= length[:, None] - 1.5 * res) & \
            (along >= self.mind.config.robot_radius)
        xs = origin[0] + d[:, 0:1] * t
        ys = origin[1] + d[:, 1:2] * t
        cells = grid.to_cell(np.stack([xs.ravel(), ys.ravel()], axis=1))
        within = grid.inside(cells)
        clear = np.zeros(len(cells), dtype=bool)
        good = cells[within]
        clear[within] = free[tuple(good.T)]
        clear = clear.reshape(xs.shape)
        if body <= 0.0:
            return np.all(clear | ~inside_ray, axis=1)
        on_ray = (along <= length[:, None]) & (along >= self.mind.config.robot_radius)
        tail = on_ray & (along >= length[:, None] - body)
        before = on_ray & ~tail
        blocked = ~clear & tail
        after_block = np.maximum.accumulate(blocked, axis=1)
        return np.all(clear | ~before, axis=1) & ~np.any(after_block & clear & tail, axis=1)


def _standpoint(pose: Sequence[float]) -> tuple[int, int]:
    """The standpoint a camera position belongs to (`STANDPOINT` m cells)."""
    return (round(pose[0] / STANDPOINT), round(pose[1] / STANDPOINT))


def _top(obj: KnownObject) -> float:
    """The height of a known support's top: the executor's rule, its detected centre is
    half-way up."""
    return 2.0 * obj.position[2]


def _disc_points(radius: float, spacing_share: float = 1.0 / 3.0) -> np.ndarray:
    """Offsets of points spread evenly over a disc of `radius` (a square grid `radius` x
    `spacing_share` apart, clipped to the disc; its centre always among them)."""
    if radius <= 0.0:
        return np.zeros((1, 2))
    step = radius * spacing_share
    n = int(math.floor(radius / step))
    axis = np.arange(-n, n + 1) * step
    xs, ys = np.meshgrid(axis, axis)
    grid = np.stack([xs.ravel(), ys.ravel()], axis=1)
    return grid[np.hypot(grid[:, 0], grid[:, 1]) <= radius + 1e-9]
