"""The executor: runs the physical and sensing steps of a plan through the robot, composed of
skills that each receive what they work with.

MOVE drives (`Driver`, `episode/driving.py`: A* legs on the robot's own grid, sensing after
each leg); CREATEVIEWCONES makes cones (`ConeSets`, `episode/cone_sets.py`); SEARCHFOROBJECT
runs a DT session against the detector (`ViewConeSearch`, `episode/dt_search.py`);
REPORTPOSITION looks at the target again first (`Verifier`, `episode/verifying.py`) and ends
the task. Assumptive steps never reach the executor. Sensing along the way (the first look
around a place, the scan after each leg, the watch for the target, confirming a detection,
glimpses) is the `Sensing` skill's (`episode/sensing.py`).

`Executor(robot, mind, builder, camera, emit, config, seed)` makes the skills' shared
`SkillContext` (`episode/context.py`) and the record of found objects (`found_sids`), and
wires the skills together: the driver senses through `Sensing.sense`, the verifier drives and
confirms through the driver and the sensing skill, a view-cone search gets all of them. The
methods and attributes the strategies, the harness and the viewers use are kept here as thin
delegates to the skills.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from avs_planner.cp.search import PlanStep
from avs_planner.cp.task import Atom
from avs_planner.episode.cone_sets import ConeSets, Location, SupportViews, WeightedCones
from avs_planner.episode.context import Event, ExecutorConfig, SkillContext, Stats
from avs_planner.episode.driving import TARGET_SEEN, Driver, Point, Pose
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.landmarks import RoomLandmarks, landmark_labels
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.outcome import SeenLike, StepOutcome, StepStatus
from avs_planner.episode.robot_api import Robot
from avs_planner.episode.sensing import Sensing
from avs_planner.episode.state_builder import AvsState, StateBuilder
from avs_planner.episode.verifying import Verifier
from avs_planner.episode.viewcones import CameraModel, ConeSet
from conceptual_map.metric import distance_field
from conceptual_map.metric.path_planning import PathResult

if TYPE_CHECKING:  # the DT (pomdp-py) is imported by the first SEARCHFOROBJECT, not before
    from avs_planner.dt import DTSession
    from avs_planner.episode.dt_search import ViewConeSearch

__all__ = ["Event", "Executor", "ExecutorConfig", "Stats"]


class Executor:
    """Runs plan steps; `emit(type, **fields)` records trace events."""

    def __init__(self, robot: Robot, mind: Mind, builder: StateBuilder, camera: CameraModel,
                 emit: Event, config: ExecutorConfig | None = None, seed: int = 0) -> None:
        config = config or ExecutorConfig()
        self.context = SkillContext(robot, mind, builder, camera, config, Stats(), emit, seed)
        # known object id -> the detection's id (the summary checks it against the world)
        self.found_sids: dict[str, int] = {}
        self.sensing = Sensing(self.context, self.found_sids, watching=config.watch)
        self.driver = Driver(self.context, sense=self.sensing.sense)
        self.verifier = Verifier(self.context, self.driver, self.sensing)
        self.cone_sets = ConeSets(self.context)
        self.on_look: Callable[[], None] | None = None  # before each DT look (e.g. depth)
        self.dt_session: DTSession | None = None  # the last SEARCHFOROBJECT's (for observers)
        if config.glimpses:
            self.enable_glimpses()
        self.landmarks: RoomLandmarks | None = None
        if config.landmarks:
            self.enable_landmarks()

    # ---- the context and the skills' state, as the strategies and the harness read it -------

    @property
    def robot(self) -> Robot:
        return self.context.robot

    @robot.setter
    def robot(self, robot: Robot) -> None:
        self.context.robot = robot

    @property
    def config(self) -> ExecutorConfig:
        return self.context.config

    @config.setter
    def config(self, config: ExecutorConfig) -> None:
        self.context.config = config

    @property
    def mind(self) -> Mind:
        return self.context.mind

    @property
    def builder(self) -> StateBuilder:
        return self.context.builder

    @property
    def camera(self) -> CameraModel:
        return self.context.camera

    @property
    def emit(self) -> Event:
        return self.context.emit

    @property
    def stats(self) -> Stats:
        return self.context.stats

    @property
    def seed(self) -> int:
        return self.context.seed

    @property
    def watching(self) -> bool:
        """The detector looks for the target as the robot moves (`Sensing.watch`)."""
        return self.sensing.watching

    @watching.setter
    def watching(self, on: bool) -> None:
        self.sensing.watching = on

    @property
    def glimpses(self) -> Glimpses | None:
        return self.sensing.glimpses

    @property
    def seen_while_moving(self) -> dict[str, set[Atom]]:
        return self.sensing.seen_while_moving

    @property
    def cones(self) -> dict[Location, ConeSet]:
        return self.cone_sets.cones

    @property
    def cone_basis(self) -> dict[Location, float]:
        return self.cone_sets.basis

    @property
    def support_views(self) -> SupportViews | None:
        """A replacement of the 2D support cones (`ConeSets.support_views`)."""
        return self.cone_sets.support_views

    @support_views.setter
    def support_views(self, views: SupportViews | None) -> None:
        self.cone_sets.support_views = views

    @property
    def qsr_cones(self) -> WeightedCones | None:
        """QSR-weighted cones (`strategies/switching/qsr_cones.install`)."""
        return self.cone_sets.qsr_cones

    @qsr_cones.setter
    def qsr_cones(self, cones: WeightedCones | None) -> None:
        self.cone_sets.qsr_cones = cones

    # ---- the skills' methods other parts call -----------------------------------------------

    def enable_glimpses(self) -> None:
        """Frames taken in passing become evidence (`Sensing.enable_glimpses`)."""
        self.sensing.enable_glimpses()

    def enable_landmarks(self) -> None:
        """Every frame also asks for room landmarks (`episode/landmarks.py`); once."""
        if self.landmarks is not None:
            return
        # the frames' geometry (field of view, range, line of sight): the glimpses' own, or
        # the same without their evidence when glimpses are off
        views = self.glimpses or Glimpses(self.mind, self.camera, 1.0,
                                          support_body=self.config.support_radius)
        labels = landmark_labels(self.mind.cmap.knowledge, self.builder.labels)
        self.landmarks = RoomLandmarks(self.context, labels, self.sensing.known_near, views)
        self.context.listeners.append(self.landmarks.listener())

    def look_around(self) -> None:
        """The first view of a place: scans both ways, the detector watching
        (`Sensing.look_around`)."""
        self.sensing.look_around()

    def sense(self, poses: list[Pose], watch: bool = False) -> KnownObject | None:
        """A scan from `poses`, the detector watching when asked or at a new place
        (`Sensing.sense`); the target the watch confirmed, if any."""
        return self.sensing.sense(poses, watch)

    def watch(self) -> KnownObject | None:
        """One look ahead for the target and the known supports (`Sensing.watch`)."""
        return self.sensing.watch()

    def confirm(self, seen: SeenLike, needed: int | None = None,
                frames: int | None = None, agree: float | None = None) -> bool:
        """More frames see `seen`'s label again where it was (`Sensing.confirm`)."""
        return self.sensing.confirm(seen, needed, frames, agree)

    def known_near(self, seen: SeenLike) -> bool:
        """A detection of an object the mind already knows (same label, within
        `same_object` metres; `Sensing.known_near`)."""
        return self.sensing.known_near(seen)

    def verify_report(self, obj: KnownObject | SeenLike) -> bool:
        """`verify`, stepping back first to where it means something
        (`Verifier.verify_report`)."""
        return self.verifier.verify_report(obj)

    def verify(self, obj: KnownObject | SeenLike) -> bool:
        """Face `obj` and see it again before it is reported (`Verifier.verify`)."""
        return self.verifier.verify(obj)

    def drive_to(self, goal: Point, stop: Callable[[], bool] = lambda: False) -> StepOutcome:
        """Drive leg by leg to `goal` (`Driver.drive_to`)."""
        return self.driver.drive_to(goal, stop)

    def squeeze_path(self, start: Point, goal: Point) -> tuple[PathResult, float]:
        """A path with a slimmer margin, and the margin (`Driver.squeeze_path`)."""
        return self.driver.squeeze_path(start, goal)

    def squeeze_margin(self) -> float:
        """The slimmest margin a path may keep (`Driver.squeeze_margin`)."""
        return self.driver.squeeze_margin()

    def create_cones(self, label: str, relation: str, location: str,
                     p: float | None = None) -> StepOutcome:
        """CREATEVIEWCONES (`ConeSets.create`)."""
        return self.cone_sets.create(label, relation, location, p)

    def location_belief(self, label: str, relation: str, location: str) -> float:
        """The map's P(ObjectAt) of the location itself (`ConeSets.location_belief`)."""
        return self.cone_sets.location_belief(label, relation, location)

    def cones_now(self, label: str, relation: str, location: str) -> ConeSet | None:
        """The cone set of a location as the looks since it was made left it
        (`ConeSets.now`)."""
        return self.cone_sets.now(label, relation, location)

    def view_cone_search(self, label: str, relation: str, location: str) -> ViewConeSearch:
        """One SEARCHFOROBJECT's DT session over the cones, with this executor's skills."""
        from avs_planner.episode.dt_search import ViewConeSearch

        return ViewConeSearch(self.context, self.driver, self.sensing, self.cone_sets,
                              self.found_sids, label, relation, location,
                              on_look=self.on_look, on_session=self._session_started)

    def _session_started(self, session: DTSession) -> None:
        self.dt_session = session

    # ---- steps ------------------------------------------------------------------------------

    def run(self, step: PlanStep, state: AvsState,
            assumed: dict[str, str] | None = None) -> StepOutcome:
        """Execute one step; `assumed` maps rooms to the category the plan assumes for them.
        Targets the detector confirmed on the way come back in the outcome's `observed`."""
        outcome = self._run(step, state, assumed)
        seen = self.sensing.take_seen()
        if seen:
            outcome.observed = {**seen, **outcome.observed}
        return outcome

    def _run(self, step: PlanStep, state: AvsState,
             assumed: dict[str, str] | None = None) -> StepOutcome:
        name = step.name.lower()
        if name == "move":
            return self.move(step.args[1], state)
        if name.startswith("createviewcones"):
            relation = name.rsplit("-", 1)[1]
            p = self.cone_sets.target_probability(step.args[0], relation, step.args[1], state,
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
                # a false detection, or a real one the verification's frames missed:
                # forgotten, so the planner searches on without it, and kept as a spot to
                # look at once more before the search gives up
                self.mind.forget_object(obj.id)
                self.mind.unverified.append((obj.label, obj.position))
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

    def search(self, label: str, relation: str, location: str) -> StepOutcome:
        """SEARCHFOROBJECT: a DT session over the cones CREATEVIEWCONES made; its duration
        prices later searches of its kind (`StateBuilder.observe_search_time`)."""
        start = self.robot.clock
        outcome = self.view_cone_search(label, relation, location).run()
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
