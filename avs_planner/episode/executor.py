"""The executor: runs the physical and sensing steps of a plan through the robot adapter.

MOVE drives A* legs on the robot's own grid, scanning and growing the maps after each leg
(`episode/driving.py`);
CREATEVIEWCONES samples cones; SEARCHFOROBJECT runs a DT session against the detector;
REPORTPOSITION ends the task. Assumptive steps never reach the executor.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

from avs_planner.cp.search import DEFAULT_REWARD, PlanStep
from avs_planner.cp.task import Atom
from avs_planner.dt import DetectorModel
from avs_planner.episode.driving import TARGET_SEEN, Driving
from avs_planner.episode.dt_search import ViewConeSearch
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.outcome import SeenLike, StepOutcome, StepStatus
from avs_planner.episode.robot_api import Robot
from avs_planner.episode.state_builder import AvsState, StateBuilder
from avs_planner.episode.verifying import step_back, verify_distance
from avs_planner.episode.viewcones import (
    CameraModel,
    ConeSet,
    p_at_support,
    room_cones,
    support_cones,
    support_relations,
)
from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.metric import distance_field

Event = Callable[..., None]


@dataclass
class ExecutorConfig:
    """How the executor drives, looks and confirms. Defaults whose comments cite episodes were
    chosen on development worlds and seeds (generated buildings below seed 10000, Fig. 3
    noise seeds 0-99), never on the held-out range (docs/experiments.md)."""

    leg: float = 1.0  # m driven between scans
    arrive: float = 0.35  # m from a MOVE's goal counts as there
    max_legs: int = 40
    replan_legs: int = 4  # legs driven on one A* path before searching again (the map grows)
    dt_policy: str = "pouct"
    # POUCT simulations per decision. The DT's own benchmark found 50 as good as 150 on its
    # synthetic instances, but in episodes 50 rejected searches that 150 confirmed (scenario
    # f, development seeds 0-19: 16/20 found with 50, 18/20 with 150; bench/episode_bench.py)
    dt_sims: int = 150
    # a look counts as a detection only when a second frame sees the label again within
    # `agree` m (a phantom rarely repeats), so misses are likelier and phantoms rarer than
    # the camera's own 0.2 / 0.05
    detector: DetectorModel = field(
        default_factory=lambda: DetectorModel(false_negative=0.36, false_positive=0.01))
    agree: tuple[float, float] = (0.25, 0.6)  # m, for the target / for supports (whose
    # detected centre moves with the part in view)
    squeeze: float = 0.08  # m less clearance when no path keeps the full margin
    # a leg the base refuses becomes a keep-out disc and the path is planned again around
    # it, up to this many times per move; then the move fails and the CP plans around it
    detours: int = 2
    # s of robot time: the CP's goal reward R, the DT's terminal penalties; the switching
    # strategy's executor is built with its `LoopConfig.reward` (one R per episode)
    miss_penalty: float = DEFAULT_REWARD
    # the detector looks for the target as the robot moves (`watch`; the loop's `watch`)
    watch: bool = True
    support_radius: float = 0.9  # m: a detection this near a support is "on" it
    same_object: float = 1.0  # m: a detection this near a known object of its label is it
    above_support: tuple[float, float] = (-0.15, 0.45)  # m around the support's top
    doorway_clearance: float = 0.6  # m from a mapped door: no place classification there
    # a target seen outside a DT search (while moving; the baselines) is reported only when
    # this many of the next frames see it again at the same spot
    confirm_needed: int = 2
    confirm_frames: int = 3
    # a confirmation that ends one short of `confirm_needed` with at least one frame agreeing
    # is ambiguous, not a rejection: it takes up to this many more frames. A real object (hit
    # in about 70% of frames at 3.6 m with the position noise against `agree`) then passes
    # 96% of the time instead of 78%; a phantom gets there only if another frame put a phantom
    # within `agree` of it, so phantoms cost no more frames than before
    confirm_extra: int = 2
    # a DT look whose second frame does not repeat the first detection takes a third frame
    # (`episode/dt_search.py`, `ViewConeSearch._look`); the DT's detector model above stays
    # the two-frame rule's, so it now slightly over-states misses
    dt_tiebreak: bool = True
    # before the target is reported the robot faces it and looks again: at least one of
    # this many frames must see it within `agree` m (0: report without looking). Two frames
    # that agree on a phantom are rare, but over the hundreds of looks of a search for an
    # absent object they happen (1 false report in 50 absent targets on generated worlds);
    # a phantom that also repeats at that spot is practically never seen, while a real
    # object in view is missed by all three frames with the camera's 0.2 only 0.8% of times
    verify_frames: int = 3
    # frames taken in passing (looking ahead while driving, both ways at a new place) that
    # do not show the target lower P(ObjectAt) where they looked, and supports they show
    # become known (`episode/glimpses.py`); the switching strategy turns this on
    # (`Executor.enable_glimpses`), the other strategies keep their own evidence rules
    glimpses: bool = False
    # directions the detector looks in at a new place (`look_around`): 2 is ahead and behind;
    # 6 covers the whole turn with the camera's 60 degree field of view
    look_headings: int = 2


@dataclass
class Stats:
    distance: float = 0.0
    dt_calls: int = 0
    dt_decisions: list[float] = field(default_factory=list)
    views: int = 0
    path: list[tuple[float, float, float, str]] = field(default_factory=list)
    detections: list[tuple[float, float, str, bool]] = field(default_factory=list)
    found_sid: int | None = None


class Executor(Driving):
    """Runs plan steps; `emit(type, **fields)` records trace events."""

    def __init__(self, robot: Robot, mind: Mind, builder: StateBuilder, camera: CameraModel,
                 emit: Event, config: ExecutorConfig | None = None, seed: int = 0):
        self.robot, self.mind, self.builder = robot, mind, builder
        self.camera, self.emit = camera, emit
        self.config = config or ExecutorConfig()
        self.seed = seed
        self.cones: dict[tuple[str, str, str], ConeSet] = {}
        self.found_sids: dict[str, int] = {}
        self.stats = Stats()
        self.watching = self.config.watch  # the detector looks for the target as it moves
        self.support_views: Callable[..., ConeSet] | None = None  # replaces support_cones
        self.on_look: Callable[[], None] | None = None  # before each DT look (e.g. depth)
        self.seen_while_moving: dict[str, set[Atom]] = {}
        self.dt_session: Any = None  # the last SEARCHFOROBJECT's DTSession (read by observers)
        self._unplaced: list[SeenLike] = []
        # QSR-weighted support cones (strategies/switching/qsr_cones.install)
        self.qsr_cones: Any = None
        # the map's P(ObjectAt) of each cone set's location when it was made: a later
        # search of it starts from what looks since then have left (`cones_now`)
        self.cone_basis: dict[tuple[str, str, str], float] = {}
        self.glimpses: Glimpses | None = None
        if self.config.glimpses:
            self.enable_glimpses()

    def enable_glimpses(self) -> None:
        """Frames taken in passing become evidence (`episode/glimpses.py`)."""
        self.glimpses = Glimpses(self.mind, self.camera,
                                 1.0 - self.config.detector.false_negative,
                                 support_body=self.config.support_radius)

    # ---- sensing along the way --------------------------------------------------------------

    def look_around(self) -> None:
        """Scan, turn half round, scan again: the first view of a place (the place map is
        updated once, after both scans). The detector watches in `look_headings` directions
        spread evenly over the turn (2: ahead and behind)."""
        headings = max(2, self.config.look_headings)
        yaw = self.robot.pose[2]
        self.mind.integrate(self.robot.scan())
        found = self.watch()
        half = headings // 2
        for k in range(1, headings):
            if found is not None and k > half:  # the target is here: the map is done
                break
            self.robot.turn_to(yaw + 2.0 * math.pi * k / headings)
            if k == half:
                found = self._sense([self.robot.pose], watch=True) or found
            elif found is None:
                found = self.watch()

    def _sense(self, poses: list[tuple[float, float, float]], watch: bool = False
               ) -> KnownObject | None:
        """Integrate a scan from `poses`; the detector watches when asked or at a new place.
        Returns the target the watch confirmed, if any."""
        before = self.mind.place_map.current_place
        events = self.mind.sense(self.robot.scan(), poses, self.robot.clock)
        place = self.mind.place_map.current_place
        if place is not None and (place != before or place not in self.mind.classified):
            self._classify()
        seen = None
        if watch or (place is not None and place != before):
            seen = self.watch()
        if self._unplaced:
            self._place_seen()
        if events:
            kinds: dict[str, int] = {}
            for e in events:
                key = f"{e.kind.value}_{e.change.value}"
                kinds[key] = kinds.get(key, 0) + 1
            self.emit("belief", map_events=kinds)
        self._record_pose()
        return seen

    def watch(self) -> KnownObject | None:
        """Keep the detector on while moving: look ahead for the target (a second frame must
        repeat a detection); a new confirmed target becomes a known object whose atoms reach
        the monitor with the next step's outcome (it may match a virtual object). The same
        frame looks for the supports the problem knows of: a new one, confirmed, becomes a
        known object too, and a frame that shows none of a label is evidence where it looked
        (`episode/glimpses.py`)."""
        if not self.watching:
            return None
        label = self.builder.task.target
        self.robot.look(0.0, self._ahead_tilt)
        labels = [label, *self.builder.supports] if self.glimpses is not None else [label]
        frame = self.robot.detect(labels)
        first = [s for s in frame if s.label == label]
        if self.glimpses is not None:
            self._glimpse(frame, labels)
        if not first or self.known_near(first[0]):
            return None
        seen = first[0]
        again = self.confirm(seen)
        self.emit("observation", label=label, detected=bool(again), watching=True,
                  position=[round(v, 2) for v in seen.position])
        if not again:
            return None
        self._unplaced.append(seen)
        return self._place_seen()

    def _glimpse(self, frame: list[SeenLike], labels: list[str]) -> None:
        """What one frame taken in passing says: the labels it did not show are less likely
        where it looked; supports it shows (seen again in a second frame) become known."""
        assert self.glimpses is not None
        target = self.builder.task.target
        shown = {s.label for s in frame}
        unseen = [lab for lab in labels if lab not in shown]
        changed = self.glimpses.frame(self.robot.pose, 0.0, self._ahead_tilt, unseen,
                                      self._supports_of(target) if target in unseen else (),
                                      tops_label=target)
        if changed:
            self.emit("belief", glimpsed=changed)
        for seen in frame:
            if seen.label == target or self.known_near(seen):
                continue
            if self.mind.room_at(seen.position[:2]) is None:
                continue
            if not self.confirm(seen, needed=1, frames=1, agree=self.config.agree[1]):
                continue
            obj = self.mind.add_object(seen.label, seen.position)
            self.seen_while_moving[obj.id] = {
                ("label-of", obj.id, seen.label), ("detected", obj.id),
                ("related", obj.id, "in", obj.room)}
            self.emit("observation", label=seen.label, detected=True, watching=True,
                      position=[round(v, 2) for v in seen.position], object=obj.id)

    def _supports_of(self, label: str) -> list[str]:
        """Known objects `label` may lie on (the knowledge lists the relation)."""
        listed = self.mind.cmap.knowledge.relation_lambda
        return [oid for oid, obj in self.mind.objects.items()
                if (label, "on", obj.label) in listed]

    def confirm(self, seen: SeenLike, needed: int | None = None,
                frames: int | None = None, agree: float | None = None) -> bool:
        """`needed` more frames (default `confirm_needed`) of up to `frames` (default
        `confirm_frames`) see the label again within `agree` metres. Without the DT's belief,
        a report rests on this: a phantom (5% of frames, anywhere in view) that repeats twice
        at the same spot is practically never seen, while a real object missed in 1 frame of
        5 still passes 9 times in 10. One short with some frame agreeing is ambiguous: up to
        `confirm_extra` more frames are taken (once)."""
        cfg = self.config
        agree = cfg.agree[0] if agree is None else agree
        needed = cfg.confirm_needed if needed is None else needed
        frames = cfg.confirm_frames if frames is None else frames
        hits = k = 0
        extended = False
        while k < frames:
            if any(s.label == seen.label and math.dist(s.position, seen.position) <= agree
                   for s in self.robot.detect([seen.label])):
                hits += 1
            k += 1
            if hits >= needed:
                return True
            if hits + frames - k < needed:
                if extended or hits == 0 or hits < needed - 1 or cfg.confirm_extra <= 0:
                    return False
                # one short, and some frame agreed: ambiguous, so look again
                frames, extended = k + cfg.confirm_extra, True
        return False

    def verify_report(self, obj) -> bool:  # noqa: ANN001 - a known object or a Seen
        """`verify` from a camera distance where frames agree by accident at most
        `MAX_ACCIDENTAL` of the time (`episode/verifying.py`): stepping back there first when
        the robot stands closer and can reach such a spot. Without a body: `verify`."""
        body = self.mind.body
        if body is None:
            return self.verify(obj)
        x, y, _ = self.robot.pose
        distance = math.dist((x, y, body.camera_height), obj.position)
        needed = min(verify_distance(self.config.agree[0], body.hfov, body.vfov),
                     0.9 * body.detect_range)
        if distance < needed:
            stand = step_back(self.mind.grid, self.mind.config.robot_radius, self.robot.pose,
                              body.camera_height, obj.position, needed)
            self.emit("action", action="(step-back)", status="start" if stand else "failed",
                      distance=round(distance, 2), needed=round(needed, 2))
            if stand is not None:
                self.drive_to(stand)
        return self.verify(obj)

    def verify(self, obj: KnownObject) -> bool:
        """Face `obj` and look at it: True when one of `verify_frames` frames sees its label
        within `agree` m of where it was found (always True with 0 frames)."""
        frames = self.config.verify_frames
        if frames <= 0:
            return True
        x, y, _ = self.robot.pose
        dx, dy = obj.position[0] - x, obj.position[1] - y
        self.robot.turn_to(math.atan2(dy, dx))
        self.robot.look(0.0, -math.atan2(self.camera.height - obj.position[2],
                                         max(math.hypot(dx, dy), 0.1)))
        seen = self.confirm(obj, needed=1, frames=frames)
        self.emit("observation", label=obj.label, detected=seen, verifying=True,
                  position=[round(v, 2) for v in obj.position])
        return seen

    def _place_seen(self) -> KnownObject | None:
        """Confirmed detections become known objects once the place map has a room for them
        (the very first look comes before the first place)."""
        obj = None
        for seen in list(self._unplaced):
            room = self.mind.room_at(seen.position[:2])
            if room is None and seen.label == self.builder.task.target:
                # a target seen through a door is reported from here; its room (evidence
                # about the room's category) is the nearest known one until it is entered
                room = self.mind.nearest_room(seen.position[:2])
            if room is None:
                continue
            self._unplaced.remove(seen)
            obj = self.mind.add_object(seen.label, seen.position, room=room)
            self.found_sids[obj.id] = seen.id
            self.seen_while_moving[obj.id] = {
                ("label-of", obj.id, seen.label), ("detected", obj.id),
                ("related", obj.id, "in", obj.room)}
        return obj

    def known_near(self, seen: SeenLike) -> bool:
        """A detection of an object the mind already knows (same label, within
        `same_object` metres)."""
        reach = self.config.same_object
        return any(obj.label == seen.label and math.dist(obj.position[:2], seen.position[:2])
                   <= reach for obj in self.mind.objects.values())

    @property
    def _ahead_tilt(self) -> float:
        return -math.atan2(self.camera.height - self.camera.support_height,
                           self.camera.look_distance)

    def _classify(self) -> None:
        """Ask the place classifier, unless the robot stands in a doorway (it would see the
        room beyond and credit it to this place); a reading that cannot be used is a warning
        in the trace, never dropped silently."""
        if self.mind.near_door(self.robot.pose[:2], self.config.doorway_clearance):
            return
        observed = self.robot.classify_place()
        if observed is None:
            self.emit("warning", source="place_classifier", detail="no reading here")
            return
        unused = self.mind.observe_appearance(observed)
        if unused is not None:
            self.emit("warning", source="place_classifier", observed=observed, detail=unused)

    def _record_pose(self) -> None:
        x, y, yaw = self.robot.pose
        room = self.mind.room_at((x, y))
        category = ""
        if room is not None and self.mind.cmap.graph.has_room(room):
            belief = self.mind.cmap.room_category(room)
            category = max(belief, key=belief.get)
        self.stats.path.append((x, y, yaw, category))

    # ---- steps ------------------------------------------------------------------------------

    def run(self, step: PlanStep, state: AvsState,
            assumed: dict[str, str] | None = None) -> StepOutcome:
        """Execute one step; `assumed` maps rooms to the category the plan assumes for them.
        Targets the detector confirmed on the way come back in the outcome's `observed`."""
        outcome = self._run(step, state, assumed)
        if self.seen_while_moving:
            outcome.observed = {**self.seen_while_moving, **outcome.observed}
            self.seen_while_moving = {}
        return outcome

    def _run(self, step: PlanStep, state: AvsState,
             assumed: dict[str, str] | None = None) -> StepOutcome:
        name = step.name.lower()
        if name == "move":
            return self.move(step.args[1], state)
        if name.startswith("createviewcones"):
            relation = name.rsplit("-", 1)[1]
            p = self._target_probability(step.args[0], relation, step.args[1], state,
                                         assumed or {})
            return self.create_cones(step.args[0], relation, step.args[1], p)
        if name.startswith("searchforobject"):
            relation = name.rsplit("-", 1)[1]
            return self.search(step.args[0], relation, step.args[1])
        if name == "reportposition":
            obj = self.mind.objects.get(step.args[0])
            if obj is None:
                return StepOutcome(StepStatus.FAILED, f"{step.args[0]} is not a known object")
            if obj.label == self.builder.task.target and not self.verify_report(obj):
                # a false detection: forgotten, so the planner searches on without it
                self.mind.forget_object(obj.id)
                self.found_sids.pop(obj.id, None)
                return StepOutcome(StepStatus.FAILED, f"{obj.label} not seen again at "
                                   f"{_at(obj.position)} when looked at before reporting; "
                                   f"{obj.id} forgotten")
            return StepOutcome(StepStatus.FOUND, f"{obj.label} at {_at(obj.position)} in "
                               f"{obj.room}", reported=obj)
        return StepOutcome(StepStatus.FAILED, f"no skill executes {step.name}")

    def nearest_placeholder(self) -> str | None:
        """The placeholder nearest by grid path that was not given up on; when none is
        reachable with the full margin, the nearest one a squeeze reaches (as `drive_to`
        squeezes when no full-margin path is left: the grid draws an opening a few cm
        narrower than it is, and a PR2 fits a 0.8 m door with 6 cm to spare)."""
        mind = self.mind
        for margin in (mind.config.robot_radius, self.squeeze_margin()):
            field_ = distance_field(mind.grid, self.robot.pose[:2], margin)
            best, best_cost = None, math.inf
            for pid, ph in mind.place_map.placeholders.items():
                cell = mind.grid.cell_of(ph.position)
                if mind.tried_placeholders.get(pid, 0) >= \
                        self.builder.config.max_placeholder_tries or not mind.grid.contains(cell):
                    continue
                if field_[cell] < best_cost:
                    best, best_cost = pid, float(field_[cell])
            if best is not None:
                return best
        return None

    def uncertain_room(self, certain: float, skip: set[str],
                       worth: Callable[[str], bool] = lambda room: True) -> str | None:
        """The known room nearest by grid path whose most likely category is below
        `certain`, not in `skip`, for which `worth` holds."""
        mind = self.mind
        pm, cmap = mind.place_map, mind.cmap
        field_ = distance_field(mind.grid, self.robot.pose[:2], mind.config.robot_radius)
        best, best_cost = None, math.inf
        for rid, room in pm.rooms.items():
            if rid in skip or not cmap.graph.has_room(rid):
                continue
            if max(cmap.room_category(rid).values()) >= certain or not worth(rid):
                continue
            for pid in room.places & set(pm.places):
                cell = mind.grid.cell_of(pm.places[pid].position)
                if mind.grid.contains(cell) and field_[cell] < best_cost:
                    best, best_cost = rid, float(field_[cell])
        return best

    def visit_room(self, room: str, max_places: int = 4) -> StepOutcome:
        """Drive through up to `max_places` places of `room`, nearest first (each new place
        is classified on arrival)."""
        pm = self.mind.place_map
        here = self.robot.pose[:2]
        places = sorted((p for p in pm.rooms[room].places if p in pm.places),
                        key=lambda p: math.dist(pm.places[p].position, here))
        outcome = StepOutcome(StepStatus.FAILED, f"{room} has no places")
        for pid in places[:max_places]:
            if pid in pm.places:
                outcome = self.drive_to(pm.places[pid].position)
        return outcome

    def move(self, target: str, state: AvsState) -> StepOutcome:
        goal = state.positions.get(target)
        if goal is None and target in self.mind.place_map.placeholders:
            goal = self.mind.place_map.placeholders[target].position
        if goal is None:
            return StepOutcome(StepStatus.FAILED, f"{target} has no position")
        is_placeholder = target in self.mind.place_map.placeholders
        if is_placeholder:
            self.mind.tried_placeholders[target] = self.mind.tried_placeholders.get(target, 0) + 1
        status = self.drive_to(goal, stop=lambda: is_placeholder and
                               target not in self.mind.place_map.placeholders)
        if status.status is StepStatus.DONE and is_placeholder and status.detail != TARGET_SEEN:
            self.look_around()
        places = self.mind.place_map.places
        if status.status is StepStatus.DONE and target in places and \
                math.dist(self.robot.pose[:2], places[target].position) <= self.config.arrive:
            self.mind.place_map.arrive_at(target)  # arrived by the executor's test: at it
        if status.status is StepStatus.FAILED:
            self.mind.move_failed(target)
        return status

    def _target_probability(self, label: str, relation: str, location: str, state: AvsState,
                            assumed: dict[str, str]) -> float | None:
        """P(ObjectAt) of the searched location under the plan's category assumption (the
        CP's own number); None to ask the conceptual map (no assumption about the room)."""
        assumed = {**{a[1]: a[2] for a in state.atoms if a[0] == "has-category"}, **assumed}
        if relation == "on":
            support = self.mind.objects.get(location)
            if support is None or support.room not in assumed:
                return None
            key = ("p-obj-on", label, support.label, assumed[support.room])
        else:
            if location not in assumed:
                return None
            key = ("p-obj-in", label, location, assumed[location])
        return state.values.get(key)

    def create_cones(self, label: str, relation: str, location: str,
                     p: float | None = None) -> StepOutcome:
        key = f"{label}-{relation}-{location}"
        if relation == "on":
            support = self.mind.objects.get(location)
            if support is None:
                return StepOutcome(StepStatus.FAILED, f"{location} is not a known object")
            if p is None:  # on it and in it, where the knowledge puts the label
                p = p_at_support(self.mind, label, location)
            made = (self.support_views is None and self.qsr_cones
                    and self.qsr_cones.support_cones(label, support, p, key)) or \
                (self.support_views or partial(support_cones, relations=support_relations(
                    self.mind, label, support.label)))(self.mind, support, p, self.camera, key)
        else:
            if location not in self.mind.place_map.rooms:
                return StepOutcome(StepStatus.FAILED, f"{location} is not a known room")
            if p is None:
                p = self.mind.cmap.p_object_at(label, location)
            made = (self.qsr_cones and self.qsr_cones.room_cones(label, location, p, key)) or \
                room_cones(self.mind, location, label, p, self.camera, key)
        self.cones[(label, relation, location)] = made
        self.cone_basis[(label, relation, location)] = self.location_belief(
            label, relation, location)
        self.mind.cones_made.add((label, relation, location))
        self.emit("action", action="createviewcones", cones=len(made.cones),
                  coverage=round(made.coverage, 3), probability=round(p, 4))
        if not made.cones:
            return StepOutcome(StepStatus.FAILED, "no view cone reachable")
        return StepOutcome(StepStatus.DONE, f"{len(made.cones)} cones")

    def location_belief(self, label: str, relation: str, location: str) -> float:
        """The map's P(ObjectAt) of the location itself (not its supports; a support's
        spaces the knowledge puts the label in: on it, in it)."""
        try:
            if relation == "on":
                return p_at_support(self.mind, label, location)
            return self.mind.cmap.p_object_at(label, location, include_sublocations=False)
        except ConceptualError:  # a location the map no longer has: no rescaling
            return 0.0

    def cones_now(self, label: str, relation: str, location: str) -> ConeSet | None:
        """The cone set of a location, its probabilities scaled by what looks since it was
        made (searches, glimpses) left of the map's P(ObjectAt) there: a desk searched once
        is not searched again from its prior."""
        made = self.cones.get((label, relation, location))
        then = self.cone_basis.get((label, relation, location), 0.0)
        if made is None or then <= 0.0:
            return made
        scale = min(1.0, self.location_belief(label, relation, location) / then)
        if scale >= 1.0:
            return made
        cones = tuple(replace(c, probability=c.probability * scale) for c in made.cones)
        return replace(made, cones=cones, probability=made.probability * scale)

    def search(self, label: str, relation: str, location: str) -> StepOutcome:
        """SEARCHFOROBJECT: a DT session over the cones CREATEVIEWCONES made; its duration
        prices later searches of its kind (`StateBuilder.observe_search_time`)."""
        start = self.robot.clock
        outcome = ViewConeSearch(self, label, relation, location).run()
        if self.stats.dt_calls and self.robot.clock > start:
            self.builder.observe_search_time(label, relation, self.robot.clock - start)
        if outcome.status is StepStatus.FAILED:
            # no view cone of this location is one this body can stand at: searching it is
            # not something this robot can do, so it is settled for the planner (else the
            # same search is offered again from the same state, and the loop gives up)
            self.builder.cannot_search(label, relation, location)
        return outcome


def _at(position: tuple[float, ...]) -> str:
    """A position for a reader: centimetres, as the other strategies report theirs."""
    return "(" + ", ".join(f"{v:.2f}" for v in position) + ")"
