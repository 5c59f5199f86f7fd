"""The executor: runs the physical and sensing steps of a plan through the robot adapter.

MOVE drives A* legs on the robot's own grid, scanning and growing the maps after each leg
(`episode/driving.py`);
CREATEVIEWCONES samples cones; SEARCHFOROBJECT runs a DT session against the detector;
REPORTPOSITION ends the task. Assumptive steps never reach the executor.
Sensing along the way (the first look around a place, the scan after each leg, the watch for
the target, confirming and verifying a detection) is `episode/sensing.py`'s; the methods
here that other parts call hand off to it.
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
from avs_planner.episode import sensing
from avs_planner.episode.driving import TARGET_SEEN, Driving
from avs_planner.episode.dt_search import ViewConeSearch
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.outcome import SeenLike, StepOutcome, StepStatus
from avs_planner.episode.robot_api import Robot
from avs_planner.episode.state_builder import AvsState, StateBuilder
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

    # ---- sensing along the way (`episode/sensing.py`) ---------------------------------------

    def look_around(self) -> None:
        """The first view of a place: scans both ways, the detector watching
        (`sensing.look_around`)."""
        sensing.look_around(self)

    def _sense(self, poses: list[tuple[float, float, float]], watch: bool = False
               ) -> KnownObject | None:
        """A scan from `poses`, the detector watching when asked or at a new place
        (`sensing.sense`); the target the watch confirmed, if any."""
        return sensing.sense(self, poses, watch)

    def watch(self) -> KnownObject | None:
        """One look ahead for the target and the known supports (`sensing.watch`)."""
        return sensing.watch(self)

    def _supports_of(self, label: str) -> list[str]:
        """Known objects `label` may lie on (`sensing.supports_of`)."""
        return sensing.supports_of(self.mind, label)

    def confirm(self, seen: SeenLike, needed: int | None = None,
                frames: int | None = None, agree: float | None = None) -> bool:
        """More frames see `seen`'s label again where it was (`sensing.confirm`)."""
        return sensing.confirm(self.robot, self.config, seen, needed, frames, agree)

    def verify_report(self, obj) -> bool:  # noqa: ANN001 - a known object or a Seen
        """`verify`, stepping back first to where it means something
        (`sensing.verify_report`)."""
        return sensing.verify_report(self, obj)

    def verify(self, obj: KnownObject) -> bool:
        """Face `obj` and see it again before it is reported (`sensing.verify`)."""
        return sensing.verify(self, obj)

    def known_near(self, seen: SeenLike) -> bool:
        """A detection of an object the mind already knows (same label, within
        `same_object` metres)."""
        return sensing.known_near(self.mind, self.config.same_object, seen)

    def _classify(self) -> None:
        """Ask the place classifier, unless in a doorway (`sensing.classify`)."""
        sensing.classify(self.robot, self.mind, self.config.doorway_clearance, self.emit)

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
            if not status.detail and target in self.mind.place_map.placeholders:
                self._frontier_stays(target)
        places = self.mind.place_map.places
        if status.status is StepStatus.DONE and target in places and \
                math.dist(self.robot.pose[:2], places[target].position) <= self.config.arrive:
            self.mind.place_map.arrive_at(target)  # arrived by the executor's test: at it
        if status.status is StepStatus.FAILED:
            self.mind.move_failed(target)
        return status

    def _frontier_stays(self, target: str) -> None:
        """The robot stood at placeholder `target` and looked all round, and its frontier is
        still there (unknown cells the laser cannot reach from here: inside furniture,
        beyond its range): a second try from the same spot sees the same. It counts as
        tried out; before, the nearest placeholder was this one again, and an episode spent
        a look around on it again ten times (about 8 s each)."""
        self.mind.tried_placeholders[target] = max(
            self.mind.tried_placeholders.get(target, 0), self.builder.config.max_placeholder_tries)
        self.emit("belief", placeholder_stays=target,
                  reason="looked all round from it; its frontier is still there")

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
