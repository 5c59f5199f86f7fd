"""The place map (Göbelbecker et al., "A Planning Approach to Active Visual Search in Large
Environments", §2): places, paths, placeholders, doors and rooms on a networkx graph.

`PlaceMap.follow` takes the robot's poses since the last call and the current occupancy grid
and returns what changed as `MapEvent`s. It only reads the robot's own grid and poses.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import networkx as nx
import numpy as np
from scipy import ndimage

from conceptual_map.errors import MapError
from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.logodds import CellState
from conceptual_map.places import kept
from conceptual_map.places.config import PlaceMapConfig
from conceptual_map.places.doors import Opening, between_walls, crossings, openings_along
from conceptual_map.places.frontiers import FrontierRegion, frontier_regions
from conceptual_map.places.model import (
    Change,
    Door,
    EntityKind,
    MapEvent,
    Place,
    Placeholder,
    Room,
)
from conceptual_map.places.rooms import free_regions, place_groups, room_extents, room_geometry
from conceptual_map.places.tracking import match_by_distance, match_by_overlap
from conceptual_map.places.unvisited import unvisited_regions

Pose = tuple[float, float, float]


class PlaceMap:
    """The robot's topological map, grown from its path and its occupancy grid."""

    def __init__(self, config: PlaceMapConfig | None = None):
        self.config = config or PlaceMapConfig()
        self.graph = nx.Graph()
        self.places: dict[str, Place] = {}
        self.placeholders: dict[str, Placeholder] = {}
        self.doors: dict[str, Door] = {}
        self.rooms: dict[str, Room] = {}
        self.current_place: str | None = None
        self._since_current: list[np.ndarray] = []  # path points since leaving current_place
        self._openings: dict[str, Opening] = {}
        self._sides: dict[str, set[int]] = {}
        self._path: list[np.ndarray] = []
        self._counters: dict[str, int] = {}
        self._door_revision = 0  # edges remember which revision of the doors they were checked at
        # the doors that part rooms: those whose jambs are thin walls as seen from the sides
        # the path went on (`doors.between_walls`), checked again whenever the grid changed;
        # the others stay door hypotheses (e.g. the gap between pieces of furniture)
        self._walled: frozenset[str] = frozenset()
        self._walls_key: tuple | None = None
        self._extents: tuple | None = None  # (key, owner, room ids, free regions): room_extents
        self._sizes: tuple[np.ndarray, np.ndarray] | None = None  # (free regions, their sizes)
        # the grid's cell states when the free space was last probed for doors (`_doors_in_view`
        # probes again only near cells that changed since)
        self._door_probed: tuple | None = None

    # ---- public API -------------------------------------------------------------------------

    def update(self, grid: OccupancyGrid, pose: Pose, time: float = 0.0) -> list[MapEvent]:
        """The robot is now at `pose` (having driven straight from its last pose)."""
        return self.follow(grid, [pose], time)

    def follow(
        self, grid: OccupancyGrid, poses: Sequence[Pose], time: float = 0.0
    ) -> list[MapEvent]:
        """The robot drove through `poses` in order; grow the map and report what changed."""
        if not poses:
            return []
        for k, pose in enumerate(poses):
            if len(pose) < 2 or not all(math.isfinite(v) for v in pose[:2]):
                raise MapError(f"PlaceMap.follow: pose {k} must start with finite x, y: {pose!r}")
        events: list[MapEvent] = []
        points = self._trajectory(poses)
        events += self._grow_places(grid, points, time)
        events += self._find_doors(grid, points, time)
        events += self._doors_in_view(grid, poses[-1][:2], time)
        events += self._refresh_placeholders(grid, poses[-1][:2], time)
        events += self._refresh_rooms(grid, time)  # marks the door edges first
        return events

    def relocate(self) -> None:
        """The robot's next pose does not continue its last path (a new task in a building
        mapped before starts where the robot now stands): no straight leg is drawn from the
        last pose, and no place is current until the next `follow` reaches one."""
        self._path = []
        self._since_current = []
        self.current_place = None

    def export(self) -> dict[str, Any]:
        """What a later run needs to go on from this map, as plain data (`kept.export`)."""
        return kept.export(self)

    @classmethod
    def restored(cls, data: Mapping[str, Any], config: PlaceMapConfig | None = None
                 ) -> tuple[PlaceMap, list[MapEvent]]:
        """A map rebuilt from `export`'s data and the events that bring a fresh conceptual
        map up to it (`kept.restore`)."""
        return kept.restore(cls(config), data)

    def refresh(self, grid: OccupancyGrid, time: float = 0.0) -> list[MapEvent]:
        """Re-derive placeholders and rooms from the grid where the robot last was (e.g. after
        what the grid lets a robot traverse changed without a new scan: blocked spots are
        forgotten). Nothing happens before the robot's first pose."""
        if not self._path:
            return []
        here = (float(self._path[-1][0]), float(self._path[-1][1]))
        return self._refresh_placeholders(grid, here, time) + self._refresh_rooms(grid, time)

    def arrive_at(self, place_id: str) -> None:
        """The robot stands at `place_id` by its executor's own test (a move to it ended
        within arrival distance). Passing by only makes a place current within half the
        place spacing of it, so a robot that stopped short of that, or never moved because
        it already stood close enough, would still be "at" the place it left: the move to
        the new one then succeeds in no time and leaves the planner's state as it was."""
        if place_id not in self.places:
            raise MapError(f"PlaceMap.arrive_at: no place {place_id!r}")
        if place_id != self.current_place:
            self._connect(self.current_place, place_id, traversed=True)
            self._arrive(place_id)

    def room_of(self, place_id: str) -> str | None:
        """The room holding a place (or, for a placeholder, holding its attached place)."""
        if place_id in self.placeholders:
            place_id = self.placeholders[place_id].place or ""
        for room in self.rooms.values():
            if place_id in room.places:
                return room.id
        return None

    def room_extents(self, grid: OccupancyGrid) -> tuple[np.ndarray, list[str]]:
        """Each known free cell's room (`rooms.room_extents`): the free space, split at the
        doors, that the room's places stand in; 0 where no room holds a cell."""
        owner, ids, _ = self._room_extents(grid)
        return owner, ids

    def _room_extents(self, grid: OccupancyGrid) -> tuple[np.ndarray, list[str], np.ndarray]:
        """`room_extents` and the free regions they are made of, cached until the grid, the
        doors or the rooms change."""
        self._check_walls(grid)
        key = (id(grid), grid.version, self._door_revision,
               tuple(sorted((rid, room.places) for rid, room in self.rooms.items())))
        if self._extents is None or self._extents[0] != key:
            labels = free_regions(grid, self._room_door_ends())
            members = {rid: [self.places[p].position for p in sorted(room.places)
                             if p in self.places] for rid, room in self.rooms.items()}
            owner, ids = room_extents(grid, labels, members)
            self._extents = (key, owner, ids, labels)
        return self._extents[1], self._extents[2], self._extents[3]

    def room_at(self, grid: OccupancyGrid, point: tuple[float, float],
                reach: float = 1.0, nearest_place: bool = True) -> str | None:
        """The room a point of the floor plan is in: the room holding the free cell nearest
        to it within `reach` m (an object seen stands on occupied cells: a table, a shelf;
        the floor around it tells the room). None when that free space is no room's: beyond
        a door, in a room seen but not entered (an object seen there is not evidence about
        the room the robot looked from). With no free cell that near (the map around the
        point not seen yet), the room of the nearest place, as before any extent is known,
        or None without `nearest_place`."""
        if not self.rooms:
            return None
        owner, ids, labels = self._room_extents(grid)
        cell = grid.to_cell(np.asarray([point], dtype=float))[0]
        r = int(np.ceil(reach / grid.resolution))
        lo = np.maximum(cell - r, 0)
        hi = np.minimum(cell + r + 1, owner.shape)
        if np.all(hi > lo):
            window = labels[lo[0]:hi[0], lo[1]:hi[1]]
            # free space no room owns and too small for the robot to stand in is a speck
            # (a cell the laser saw between a table's legs), not a room beyond a door
            if self._sizes is None or self._sizes[0] is not labels:
                self._sizes = (labels, np.bincount(labels.ravel()))
            sizes = self._sizes[1]
            speck = (owner[lo[0]:hi[0], lo[1]:hi[1]] == 0) & \
                (sizes[window] * grid.resolution ** 2 < np.pi * self.config.robot_radius ** 2)
            candidates = np.argwhere((window > 0) & ~speck)
            if len(candidates):
                d = np.linalg.norm(candidates + lo - cell, axis=1)
                if d.min() * grid.resolution <= reach:
                    i, j = candidates[int(np.argmin(d))] + lo
                    k = int(owner[i, j])
                    return ids[k - 1] if k else None
        if not nearest_place:
            return None
        place, _ = self._nearest_place(np.asarray(point, dtype=float))
        return self.room_of(place) if place is not None else None

    def room_links(self) -> dict[str, tuple[str, str]]:
        """Door id -> the two rooms it joins (room connectivity for the conceptual map)."""
        links = {}
        for door_id in self.doors:
            rooms = sorted(r.id for r in self.rooms.values() if door_id in r.doors)
            if len(rooms) == 2:
                links[door_id] = (rooms[0], rooms[1])
        return links

    # ---- places -----------------------------------------------------------------------------

    def _new_id(self, prefix: str) -> str:
        self._counters[prefix] = self._counters.get(prefix, 0) + 1
        return f"{prefix}{self._counters[prefix]}"

    def _trajectory(self, poses: Sequence[Pose]) -> np.ndarray:
        """Points every `trajectory_step` along straight legs from the last known pose."""
        points = [np.asarray(p[:2], dtype=float) for p in poses]
        if self._path:
            points.insert(0, self._path[-1])
        out = [points[0][None, :]]
        for a, b in zip(points, points[1:], strict=False):
            n = max(1, int(math.ceil(np.linalg.norm(b - a) / self.config.trajectory_step)))
            t = np.linspace(0.0, 1.0, n + 1)[1:, None]
            out.append(a * (1 - t) + b * t)
        samples = np.vstack(out)
        if self._path:
            samples = samples[1:]
        self._path.extend(samples)
        return samples

    def _grow_places(self, grid: OccupancyGrid, points: np.ndarray, time: float) -> list[MapEvent]:
        events = []
        for p in points:
            self._since_current.append(p)
            nearest, dist = self._nearest_place(p)
            if nearest is None or dist >= self.config.place_spacing:
                events.append(self._add_place(grid, p, time))
            elif nearest != self.current_place and dist < 0.5 * self.config.place_spacing:
                self._connect(self.current_place, nearest, traversed=True)
                self._arrive(nearest)
        return events

    def _arrive(self, place_id: str) -> None:
        self.current_place = place_id
        self._since_current = [np.asarray(self.places[place_id].position)]

    def _nearest_place(self, p: np.ndarray) -> tuple[str | None, float]:
        best, best_d = None, math.inf
        for pid, place in self.places.items():
            d = math.dist(place.position, p)
            if d < best_d:
                best, best_d = pid, d
        return best, best_d

    def _add_place(self, grid: OccupancyGrid, p: np.ndarray, time: float) -> MapEvent:
        place = Place(self._new_id("place"), (float(p[0]), float(p[1])), time)
        self.places[place.id] = place
        self.graph.add_node(place.id, kind="place", pos=place.position)
        self._connect(self.current_place, place.id, traversed=True)
        free = grid.traversable(self.config.robot_radius)
        for other in self.places.values():
            near = math.dist(other.position, place.position) <= self.config.edge_max_length
            if other.id != place.id and near and not self.graph.has_edge(other.id, place.id):
                if grid.segment_clear(other.position, place.position, free):
                    self._connect(other.id, place.id, traversed=False)
        self._arrive(place.id)
        return MapEvent(EntityKind.PLACE, Change.APPEARED, place.id, place, time)

    def _connect(self, a: str | None, b: str, traversed: bool) -> None:
        if a is None or a == b:
            return
        ends = [np.asarray(self.places[a].position), np.asarray(self.places[b].position)]
        trace = np.array([ends[0], *self._since_current[1:], ends[1]]) if traversed else None
        if self.graph.has_edge(a, b):
            edge = self.graph.edges[a, b]
            edge["traversed"] |= traversed
            edge["trace"] = edge["trace"] if edge["trace"] is not None else trace
            return
        length = math.dist(self.places[a].position, self.places[b].position)
        self.graph.add_edge(a, b, length=length, traversed=traversed, door=None, trace=trace)

    # ---- doors ------------------------------------------------------------------------------

    def _find_doors(self, grid: OccupancyGrid, points: np.ndarray, time: float) -> list[MapEvent]:
        """Openings on the path just driven (they get confirmed once the path crosses them)."""
        found = openings_along(grid, points, self.config)
        return self._add_openings(found, points, time)

    def _doors_in_view(self, grid: OccupancyGrid, here: Sequence[float], time: float
                       ) -> list[MapEvent]:
        """Door hypotheses wherever the mapped free space near the robot narrows to a door's
        width, not only where the robot drove or means to: a room seen through its door from
        the corridor is parted from the corridor before the robot goes in (else its floor
        joined the corridor's room until then, and stayed joined if the robot never went
        in). Probe points: free cells, within `door_view_radius` of the robot, that the
        robot's disc fits in and where the clearance has a saddle (as clear as both
        neighbours across, no clearer than both along), one per 0.2 m square; the opening
        test is the path's. Only points within `probe_range` of a cell whose state changed
        since the last probe are probed again (what the test reads lies within that
        range)."""
        cfg, res = self.config, grid.resolution
        clear = grid.clearance()
        state = grid.state_grid()
        before = self._door_probed
        self._door_probed = (tuple(grid.origin), state.copy())
        changed = np.ones(state.shape, dtype=bool)
        if (before is not None and before[0] == tuple(grid.origin)
                and before[1].shape == state.shape):
            changed = before[1] != state
            if not changed.any():
                return []
            near = int(math.ceil(cfg.probe_range / res))
            changed = ndimage.maximum_filter(changed, size=2 * near + 1)
        centre = grid.to_cell(np.asarray([here[:2]], dtype=float))[0]
        reach = int(math.ceil(cfg.door_view_radius / res))
        lo = np.maximum(centre - reach, 0)
        hi = np.minimum(centre + reach + 1, np.asarray(clear.shape))
        if np.any(hi - lo < 3):
            return []
        window = (slice(lo[0], hi[0]), slice(lo[1], hi[1]))
        c = np.pad(clear[window], 1, mode="edge")
        mid = c[1:-1, 1:-1]

        def peak(di: int, dj: int) -> tuple[np.ndarray, np.ndarray]:
            """(as clear as both neighbours along (di, dj), no clearer than both)"""
            a = c[1 + di:c.shape[0] - 1 + di, 1 + dj:c.shape[1] - 1 + dj]
            b = c[1 - di:c.shape[0] - 1 - di, 1 - dj:c.shape[1] - 1 - dj]
            return (mid >= a) & (mid >= b), (mid <= a) & (mid <= b)

        # a saddle of the clearance: widest across the opening, narrowest along the way through
        (x_max, x_min), (y_max, y_min) = peak(1, 0), peak(0, 1)
        (d_max, d_min), (e_max, e_min) = peak(1, 1), peak(1, -1)
        ridge = (x_max & y_min) | (y_max & x_min) | (d_max & e_min) | (e_max & d_min)
        band = ((mid >= 0.5 * cfg.door_min_width - res) & (mid <= 0.5 * cfg.door_max_width)
                & (state[window] == CellState.FREE))
        standable = grid.traversable(cfg.reach_radius)[window]
        cells = np.argwhere(ridge & band & standable & changed[window]) + lo
        if cells.size == 0:
            return []
        near = np.hypot(*(cells - centre).T) <= reach
        cells = cells[near]
        block = max(1, int(round(0.2 / res)))
        _, first = np.unique(cells // block, axis=0, return_index=True)
        points = grid.to_world(cells[np.sort(first)])
        found = openings_along(grid, points, cfg, seen_beside=True)
        return self._add_openings(found, points[:0], time)

    def _add_openings(
        self, openings: list[Opening], path_points: np.ndarray, time: float
    ) -> list[MapEvent]:
        touched: dict[str, Change] = {}
        for opening in openings:
            door_id = self._merge_opening(opening)
            touched.setdefault(door_id, Change.CHANGED)
            if door_id not in self.doors:
                touched[door_id] = Change.APPEARED
        for door_id in self._openings:
            seen = path_points if door_id not in touched else self._path
            if self._note_sides(door_id, seen):
                touched.setdefault(door_id, Change.CHANGED)
        events = []
        for door_id, change in touched.items():
            door = self._door_from(door_id)
            if change is Change.CHANGED and self.doors.get(door_id) == door:
                continue
            self.doors[door_id] = door
            self._door_revision += 1
            events.append(MapEvent(EntityKind.DOOR, change, door_id, door, time))
        return events

    def _merge_opening(self, opening: Opening) -> str:
        for door_id, known in self._openings.items():
            close = np.linalg.norm(known.centre - opening.centre) < self.config.door_merge_distance
            if close:
                if opening.width < known.width - 0.01:
                    self._openings[door_id] = opening
                return door_id
        door_id = self._new_id("door")
        self._openings[door_id] = opening
        self._sides[door_id] = set()
        return door_id

    def _note_sides(self, door_id: str, points: Sequence[np.ndarray] | np.ndarray) -> bool:
        """Record on which sides of the door the path went; True if a new side was seen."""
        opening, seen = self._openings[door_id], self._sides[door_id]
        before = len(seen)
        pts = np.asarray(points)
        if pts.size == 0:
            return False
        rel = pts - opening.centre
        along, across = rel @ opening.axis, rel @ opening.normal
        near = (np.abs(along) <= 0.5 * opening.width) & (np.abs(across) <= 1.5)
        seen.update(int(s) for s in np.sign(across[near & (np.abs(across) >= 0.2)]))
        return len(seen) != before

    def _door_from(self, door_id: str) -> Door:
        opening = self._openings[door_id]
        a, b = opening.ends()
        return Door(
            id=door_id,
            centre=(float(opening.centre[0]), float(opening.centre[1])),
            width=round(opening.width, 3),
            ends=((float(a[0]), float(a[1])), (float(b[0]), float(b[1]))),
            confirmed=len(self._sides[door_id]) == 2,
        )

    def _check_walls(self, grid: OccupancyGrid) -> None:
        """Which doors part rooms (`_walled`), again if the grid or the doors changed."""
        sides = {k: tuple(sorted(self._sides.get(k, ()))) for k in self.doors}
        key = (id(grid), grid.version,
               tuple(sorted((k, d.ends, sides[k]) for k, d in self.doors.items())))
        if key == self._walls_key:
            return
        self._walls_key = key
        state = grid.state_grid()
        walled = frozenset(k for k, d in self.doors.items() if between_walls(
            grid, d.ends, self.config.door_max_depth, sides[k], state))
        if walled != self._walled:
            self._walled = walled
            self._door_revision += 1

    def _room_door_ends(self) -> list:
        return [self.doors[k].ends for k in sorted(self._walled) if k in self.doors]

    def _mark_door_edges(self) -> None:
        """An edge passes a door if its straight line does, or (if driven) the path driven does.
        Only doors that part rooms count (`_check_walls`)."""
        for u, v, data in self.graph.edges(data=True):
            if u not in self.places or v not in self.places:
                continue
            if data.get("doors_checked") == self._door_revision:
                continue
            a, b = np.asarray(self.places[u].position), np.asarray(self.places[v].position)
            lines = [np.array([a, b])]
            if data["trace"] is not None:
                lines.append(data["trace"])
            crossed = (  # an even number of crossings comes back to the same side
                d.id
                for d in self.doors.values()
                if d.id in self._walled and any(crossings(ln, d.ends) % 2 == 1 for ln in lines)
            )
            data["door"] = next(crossed, None)
            data["doors_checked"] = self._door_revision

    # ---- placeholders -----------------------------------------------------------------------

    def _refresh_placeholders(
        self, grid: OccupancyGrid, robot: tuple[float, float], time: float
    ) -> list[MapEvent]:
        regions = frontier_regions(grid, robot, self.config) if self.places else []
        regions += unvisited_regions(
            grid, robot, [p.position for p in self.places.values()],
            [d.ends for d in self.doors.values()], self.config,
            covered=[r.standpoint for r in regions],
        )
        old = {k: v.frontier_centre for k, v in self.placeholders.items()}
        matched = match_by_distance(
            old, [r.centre for r in regions], self.config.placeholder_match_distance
        )
        ids = [matched.get(i) or self._new_id("placeholder") for i in range(len(regions))]
        events = self._doors_toward(grid, regions, ids, time)
        kept = set()
        for pid, region in zip(ids, regions, strict=True):
            kept.add(pid)
            new = self._placeholder(pid, region)
            prev = self.placeholders.get(pid)
            if prev is None:
                events.append(MapEvent(EntityKind.PLACEHOLDER, Change.APPEARED, pid, new, time))
            elif _moved(prev, new):
                events.append(MapEvent(EntityKind.PLACEHOLDER, Change.CHANGED, pid, new, time))
            self._set_placeholder(new)
        for pid in set(self.placeholders) - kept:
            gone = self.placeholders.pop(pid)
            self.graph.remove_node(pid)
            events.append(MapEvent(EntityKind.PLACEHOLDER, Change.VANISHED, pid, gone, time))
        return events

    def _doors_toward(
        self, grid: OccupancyGrid, regions: list[FrontierRegion], ids: list[str], time: float
    ) -> list[MapEvent]:
        """Door hypotheses (not yet passed) on the way from a place to a new or moved frontier,
        like the active visual search paper's per-scan door detector; passing through later
        confirms them."""
        probes = []
        for pid, region in zip(ids, regions, strict=True):
            prev = self.placeholders.get(pid)
            if prev is not None and math.dist(prev.position, region.standpoint) <= 0.2:
                continue
            probes.append(self._approach(region))
        if not probes:
            return []
        points = np.vstack(probes)
        cells = grid.to_cell(points)
        standable = grid.inside(cells)
        standable[standable] = grid.traversable(self.config.reach_radius)[
            cells[standable, 0], cells[standable, 1]
        ]
        points = points[standable]  # a robot could pass here, as through a door
        found = openings_along(grid, points, self.config)
        return self._add_openings(found, points[:0], time)

    def _approach(self, region: FrontierRegion) -> np.ndarray:
        """Points every 10 cm from the nearest place via the standpoint to the frontier."""
        place, _ = self._nearest_place(np.asarray(region.standpoint))
        corners = [region.standpoint, region.centre]
        if place is not None:
            corners.insert(0, self.places[place].position)
        return _densify(np.asarray(corners, dtype=float), 0.1)

    def _placeholder(self, pid: str, region: FrontierRegion) -> Placeholder:
        approach = self._approach(region)
        place, _ = self._nearest_place(np.asarray(region.standpoint))
        near_door = next(
            (
                d.id
                for d in self.doors.values()
                if math.dist(d.centre, region.centre) <= 1.0 or crossings(approach, d.ends) > 0
            ),
            None,
        )
        return Placeholder(
            id=pid,
            position=region.standpoint,
            frontier_centre=region.centre,
            frontier_length=round(region.length, 3),
            open_space=round(region.open_space, 3),
            place=place,
            near_door=near_door,
        )

    def _set_placeholder(self, ph: Placeholder) -> None:
        if ph.id in self.graph:
            self.graph.remove_node(ph.id)
        self.placeholders[ph.id] = ph
        self.graph.add_node(ph.id, kind="placeholder", pos=ph.position)
        if ph.place is not None:
            length = math.dist(self.places[ph.place].position, ph.position)
            self.graph.add_edge(
                ph.place, ph.id, length=length, traversed=False, door=None, trace=None
            )

    # ---- rooms ------------------------------------------------------------------------------

    def _refresh_rooms(self, grid: OccupancyGrid, time: float) -> list[MapEvent]:
        self._check_walls(grid)
        self._mark_door_edges()
        groups = place_groups(self.graph)
        matched = match_by_overlap({k: set(r.places) for k, r in self.rooms.items()}, groups)
        labels = free_regions(grid, self._room_door_ends())
        events, kept = [], set()
        for i, members in enumerate(groups):
            rid = matched.get(i) or self._new_id("room")
            kept.add(rid)
            room = self._room(rid, members, grid, labels)
            prev = self.rooms.get(rid)
            self.rooms[rid] = room
            if prev is None:
                events.append(MapEvent(EntityKind.ROOM, Change.APPEARED, rid, room, time))
            elif _room_changed(prev, room):
                events.append(MapEvent(EntityKind.ROOM, Change.CHANGED, rid, room, time))
        for rid in set(self.rooms) - kept:
            gone = self.rooms.pop(rid)
            events.append(MapEvent(EntityKind.ROOM, Change.VANISHED, rid, gone, time))
        return events

    def _room(self, rid: str, members: set[str], grid: OccupancyGrid, labels: np.ndarray) -> Room:
        doors = {
            door
            for u, v, door in self.graph.edges(data="door")
            if door is not None and (u in members or v in members)
        }
        area, elongation = room_geometry(
            grid, labels, [self.places[p].position for p in sorted(members)]
        )
        return Room(rid, frozenset(members), frozenset(doors), round(area, 3), round(elongation, 3))


def _densify(corners: np.ndarray, step: float) -> np.ndarray:
    """Points at most `step` apart along the polyline through `corners` (K, 2)."""
    out = [corners[:1]]
    for a, b in zip(corners[:-1], corners[1:], strict=True):
        n = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
        t = np.linspace(0.0, 1.0, n + 1)[1:, None]
        out.append(a * (1 - t) + b * t)
    return np.vstack(out)


def _moved(prev: Placeholder, new: Placeholder) -> bool:
    shifted = math.dist(prev.position, new.position) > 0.2
    grown = abs(prev.open_space - new.open_space) > 0.25 * max(prev.open_space, 1e-9)
    return shifted or grown or prev.place != new.place or prev.near_door != new.near_door


def _room_changed(prev: Room, new: Room) -> bool:
    resized = abs(prev.area - new.area) > 0.5 or abs(prev.elongation - new.elongation) > 0.1
    return prev.places != new.places or prev.doors != new.doors or resized
