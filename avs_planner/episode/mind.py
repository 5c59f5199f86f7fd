"""The robot's mind during an episode: its maps, conceptual map and confirmed objects.

Everything here is fed with sensor data only (scans, poses, place-classifier outputs,
detections the DT planner confirmed); nothing reads the simulator. The state builder turns a
`Mind` into a PDDL problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from avs_planner.body import RobotBody
from avs_planner.episode.blockages import Blockage, Blockages, NarrowOpening, narrow_openings
from avs_planner.episode.placeholder_outcomes import PlaceholderOutcomes
from conceptual_map.conceptual import ConceptualMap, RelatedSpace
from conceptual_map.conceptual.place_events import PlaceMapFeed
from conceptual_map.knowledge import Knowledge
from conceptual_map.metric import OccupancyGrid, VoxelMap
from conceptual_map.metric.sensors import DepthFrameLike, LaserScanLike
from conceptual_map.places import MapEvent, PlaceMap, PlaceMapConfig

Pose = tuple[float, float, float]


SQUEEZE = 0.08  # m: at most this much less than the planning radius when squeezing


def squeeze_radius(body: RobotBody, resolution: float) -> float:
    """The slimmest disc the mind plans a squeeze through a gap with: the planning radius
    less `SQUEEZE`, never below the footprint less one grid cell (the grid's clearance
    under-estimates the distance to a surface by up to about a cell: a gap the body passes
    can look up to ~0.1 m narrower than it is). A squeeze the base refuses is a blockage."""
    return round(max(body.planning_radius - SQUEEZE, body.footprint_radius - resolution), 3)


@dataclass(frozen=True)
class KnownObject:
    """An object the DT planner confirmed: `support` is the object it stands on, if any."""

    id: str
    label: str
    position: tuple[float, float, float]
    room: str
    support: str | None = None


@dataclass
class Mind:
    """Occupancy grid, place map, conceptual map (fed by place-map events), known objects.

    Without a body it plans for a Pioneer-sized disc (0.30 m); `Mind.for_body` plans for the
    robot's own footprint (`RobotBody.planning_radius`)."""

    config: PlaceMapConfig = field(default_factory=lambda: PlaceMapConfig(
        robot_radius=0.3))
    body: RobotBody | None = None
    knowledge: Knowledge | None = None
    resolution: float = 0.05
    grid: OccupancyGrid = field(init=False)
    place_map: PlaceMap = field(init=False)
    cmap: ConceptualMap = field(init=False)
    objects: dict[str, KnownObject] = field(default_factory=dict)
    cones_made: set[tuple[str, str, str]] = field(default_factory=set)
    tried_placeholders: dict[str, int] = field(default_factory=dict)
    classified: set[str] = field(default_factory=set)
    voxel_resolution: float = 0.05
    voxel_heights: tuple[float, float] = (-0.1, 2.5)  # m: the band the 3D map covers
    voxels: VoxelMap | None = field(default=None, init=False)
    blockages: Blockages = field(default_factory=Blockages)
    # (place, move target) -> the blockage evidence when that move failed from that place:
    # while the robot stands there with the same evidence, the move is not offered again
    failed_moves: dict[tuple[str, str], frozenset[str]] = field(default_factory=dict)
    blocked_retries: int = 0  # times the blocked spots were forgotten (`retry_blocked`)
    clock: float = 0.0  # s: the time of the last scan sensed
    # object id -> the clock when it was confirmed (what the building memory keeps with it)
    seen_at: dict[str, float] = field(default_factory=dict)
    # sightings from the building memory not checked yet (`episode/memory.py`): never
    # known objects, so nothing is reported from memory alone
    remembered: list = field(default_factory=list)
    # (label, position) of targets confirmed by frames that the verification before the
    # report then missed: forgotten as objects, looked at once more before the search gives
    # up (`strategies/switching/recovery.py`, `recheck_unverified`)
    unverified: list[tuple[str, tuple[float, float, float]]] = field(default_factory=list)
    # (grid and rooms key, `viewcones.candidate_cells`' result): recomputed when either changes
    cell_cache: tuple | None = field(default=None, init=False, repr=False, compare=False)
    # vanished placeholders until the map tells what lay behind them: the building's
    # evidence about its placeholders (`episode/placeholder_outcomes.py`)
    placeholder_outcomes: PlaceholderOutcomes = field(default_factory=PlaceholderOutcomes,
                                                      repr=False, compare=False)

    def __post_init__(self) -> None:
        self.grid = OccupancyGrid(resolution=self.resolution)
        self.place_map = PlaceMap(self.config)
        self.cmap = ConceptualMap(self.knowledge)
        self._feed = PlaceMapFeed(self.cmap)

    @classmethod
    def for_body(cls, body: RobotBody, knowledge: Knowledge | None = None) -> Mind:
        """A mind that plans for `body`'s footprint (from the robot model, never the world)."""
        return cls(config=PlaceMapConfig(robot_radius=body.planning_radius,
                                         squeeze_radius=squeeze_radius(body, cls.resolution)),
                   body=body, knowledge=knowledge)

    @property
    def passing_width(self) -> float:
        """The narrowest opening, as the grid measures it (`NarrowOpening.width`), the mind
        tries to pass: its squeeze disc plus the grid's half-cell under-estimate each side."""
        return 2.0 * (self.config.reach_radius + self.grid.resolution / math.sqrt(2.0))

    # ---- blocked moves ----------------------------------------------------------------------

    def block(self, touch: tuple[float, float], time: float) -> Blockage:
        """The base's rim touched something at `touch`: keep clear of it for a while."""
        blockage = self.blockages.add(touch, time, self.place_map.doors,
                                      self.config.robot_radius)
        self.grid.set_keep_out(self.blockages.discs())
        return blockage

    def forget_blockages(self, time: float) -> list[Blockage]:
        """Blockages past their retry time are tried again."""
        gone = self.blockages.expire(time)
        if gone:
            self.grid.set_keep_out(self.blockages.discs())
        return gone

    def retry_blocked(self, limit: int | None = None) -> list[Blockage]:
        """Forget the active blockages now (nothing else is left to try), at most `limit`
        times per episode (each touch there widens the berth, so retrying ends). The
        placeholders are re-derived at once: space that only a kept-out spot cut off is a
        goal again (else the planner would see none until the next scan, and give up)."""
        if limit is not None and self.blocked_retries >= limit:
            return []
        gone = self.blockages.clear()
        if gone:
            self.blocked_retries += 1
            self.grid.set_keep_out([])
            before = self.placeholder_outcomes.snapshot(self.cmap, self.place_map)
            self._apply(before, self.place_map.refresh(self.grid, self.clock))
        return gone

    def move_failed(self, target: str) -> None:
        """A move to `target` failed from the current place, with today's evidence."""
        here = self.place_map.current_place
        if here is not None:
            self.failed_moves[(here, target)] = self.blockages.signature()

    def move_withheld(self, place: str, target: str) -> bool:
        """The move failed from `place` and nothing was learned since (by construction it is
        not offered again: no identical failed move from an unchanged state)."""
        return self.failed_moves.get((place, target)) == self.blockages.signature()

    def narrow_openings(self, robot: tuple[float, float]) -> list[NarrowOpening]:
        """Openings on the way to seen free space that are narrower than the robot passes."""
        return narrow_openings(self.grid, robot, self.config.reach_radius,
                               self.place_map.doors)

    def sense(self, scan: LaserScanLike, poses: list[Pose], time: float) -> list[MapEvent]:
        """Integrate a scan taken at the end of `poses` and grow the place map along them."""
        self.clock = max(self.clock, time)
        self.forget_blockages(time)
        self.grid.integrate_scan(scan)
        before = self.placeholder_outcomes.snapshot(self.cmap, self.place_map)
        events = self.place_map.follow(self.grid, poses, time)
        self._apply(before, events)
        if events:
            self._place_objects()
        self._drop_stale_objects()
        return events

    def _apply(self, before: tuple, events: list[MapEvent]) -> None:
        """Feed a batch of place-map events to the conceptual map, and what the map now
        tells of vanished placeholders (`episode/placeholder_outcomes.py`; `before`: the
        snapshot taken before the batch)."""
        self._feed.apply(events)
        self.placeholder_outcomes.update(before, events, self.cmap, self.place_map, self.grid)

    def integrate(self, scan: LaserScanLike) -> None:
        """Integrate a scan into the grid only (the next `sense` grows the place map; one
        place-map update after several scans from one spot gives the same places)."""
        self.grid.integrate_scan(scan)

    def integrate_depth(self, frame: DepthFrameLike) -> VoxelMap:
        """Add a depth frame to the 3D map, which covers the 2D grid's extent (grown with it)
        over `voxel_heights`; rays leaving that band are cut at its border."""
        lo = np.asarray(self.grid.origin, dtype=float)
        hi = lo + np.asarray(self.grid.shape) * self.grid.resolution
        z0, z1 = self.voxel_heights
        if self.voxels is None:
            self.voxels = VoxelMap(origin=(lo[0], lo[1], z0),
                                   size=(hi[0] - lo[0], hi[1] - lo[1], z1 - z0),
                                   resolution=self.voxel_resolution)
        else:
            mid = (z0 + z1) / 2
            self.voxels.ensure_contains(np.array([[lo[0], lo[1], mid], [hi[0], hi[1], mid]]))
        self.voxels.integrate_depth(frame)
        return self.voxels

    def observe_appearance(self, observed: str) -> str | None:
        """The place classifier said `observed` at the current place: None when the reading
        became evidence, else why it could not be used (the caller reports it)."""
        place = self.place_map.current_place
        if place is None or not self.cmap.graph.has_place(place):
            return f"no place to credit the reading {observed!r} to yet"
        value = f"{observed}_like"
        model = self.cmap.knowledge.properties.get("appearance")
        if model is None:
            return "the knowledge base has no 'appearance' property"
        if value not in model.values:
            return (f"the knowledge base has no appearance value {value!r} (known: "
                    f"{', '.join(model.values)})")
        self.cmap.observe_property(place, "appearance", value)
        self.classified.add(place)
        return None

    def near_door(self, position: tuple[float, float], clearance: float) -> bool:
        """Whether `position` is within `clearance` of a door the robot has mapped (a reading
        taken in a doorway may see the room on the other side)."""
        return any(math.dist(d.centre, position) < clearance
                   for d in self.place_map.doors.values())

    def room_at(self, position: tuple[float, float], floor_only: bool = False) -> str | None:
        """The room whose mapped floor holds `position` (`PlaceMap.room_at`): None beyond a
        door the robot has not passed. The room of the nearest place credited a kitchen's
        table and cereal box seen through its door to the corridor the robot looked from, and
        the corridor's readings then outweighed them (the room ended "corridor 1.00").
        `floor_only`: None too where no mapped floor is near (else the nearest place's room)."""
        return self.place_map.room_at(self.grid, position, nearest_place=not floor_only)

    def nearest_room(self, position: tuple[float, float]) -> str | None:
        """The room of the place nearest to `position` (None before any room exists)."""
        best, best_d = None, math.inf
        for pid, place in self.place_map.places.items():
            d = math.dist(place.position, position)
            if d < best_d and self.place_map.room_of(pid) is not None:
                best, best_d = pid, d
        return self.place_map.room_of(best) if best is not None else None

    def add_object(self, label: str, position: tuple[float, float, float],
                   support: str | None = None, room: str | None = None) -> KnownObject:
        """A confirmed detection becomes a known object (and evidence for its room: the
        support's, else `room`, else the room whose floor holds it)."""
        room = (self.objects[support].room if support is not None
                else room or self.room_at(position[:2]))
        if room is None:
            raise ValueError(f"no room known near {position[:2]}")
        n = len(self.objects) + 1
        while f"object{n}" in self.objects or f"object{n}" in self.cmap.objects.objects:
            n += 1
        oid = f"object{n}"
        self.cmap.observe_object(label, room, on=support, object_id=oid)
        known = KnownObject(oid, label, position, room, support)
        self.objects[oid] = known
        self.seen_at[oid] = self.clock
        return known

    def forget_object(self, oid: str) -> None:
        """A known object proved a false detection: the mind and the map drop it."""
        self.cmap.forget_object(oid)
        self.objects.pop(oid, None)
        self.seen_at.pop(oid, None)

    def searched(self, label: str, relation: str, location: str, coverage: float,
                 p_detect: float) -> None:
        """A DT search looked through `coverage` of a location: the `label` objects not seen
        there are Poisson(lambda x remaining), whatever it found (Poisson thinning)."""
        if relation == "on":
            where: str | RelatedSpace = RelatedSpace(relation, location)
        else:
            room = self.cmap.current_room(location)
            if room is None:  # the map removed the room while the search ran: nothing to
                return        # attach what it saw to (a merged room passes it to its heir)
            where = room
        self.cmap.observe_search(label, where, min(1.0, coverage), p_detect)

    def _place_objects(self) -> None:
        """Objects stand where the map now puts their floor: one seen through a door before
        the space beyond was a room of its own was credited to the room the robot looked
        from (a kitchen's table to the corridor, which stayed "corridor 1.00" and the kitchen
        without its table); once the map parts that space into its own room, the object and
        what stands on it move there, and both rooms' evidence with them."""
        for oid, obj in list(self.objects.items()):
            if obj.support is not None:
                continue  # it moves with its support
            room = self.room_at(obj.position[:2], floor_only=True)
            record = self.cmap.objects.objects.get(oid)
            if room is None or record is None or room == record.room \
                    or not self.cmap.graph.has_room(room):
                continue
            self.cmap.move_object(oid, room)

    def _drop_stale_objects(self) -> None:
        """Rooms merge as the map grows: keep objects' rooms in step with the ledger."""
        for oid, obj in list(self.objects.items()):
            record = self.cmap.objects.objects.get(oid)
            if record is not None and record.room != obj.room:
                self.objects[oid] = KnownObject(oid, obj.label, obj.position, record.room,
                                                obj.support)
