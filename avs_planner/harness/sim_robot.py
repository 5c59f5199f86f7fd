"""The robot side: the only module of the episode package that talks to the simulator.

`SimRobot` hands the mind sensor data only (pose, laser scans, detections, place-classifier
outputs, the clock). Ground truth stays here: `truth_of` keeps each detection's world entry
for the summary's evaluation, never for planning.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matplotlib.path import Path as MplPath

from avs_planner.body import PLANNING_CLEARANCE, JointRange, RobotBody
from avs_planner.episode.errors import EpisodeError
from sim import World, load_world_spec
from sim.errors import MotionError, PathBlockedError, SimError
from sim.robot_models import ROBOT_MODELS
from sim.world_spec import RoomSpec, WorldSpec

# The Pioneer's mind keeps the 0.30 m disc (0.26 + 0.04) the runs of the active visual search
# paper's Fig. 3 a-f were tuned with (its doors are 0.9 m, the margin costs it nothing); other
# bodies keep PLANNING_CLEARANCE.
_CLEARANCE = {"pioneer": 0.04}


@dataclass(frozen=True)
class Seen:
    """One detection as the mind sees it: label, 3D position, confidence, and an id."""

    id: int
    label: str
    position: tuple[float, float, float]
    confidence: float


class SimRobot:
    """Wraps a `sim.World`: motion, sensing and the clock, with sensor data out."""

    def __init__(self, world: World):
        self.world = world
        self.robot = world.robot
        self.truth_of: dict[int, str | None] = {}
        self.model = self.robot.model.name
        self.last_contact: tuple[float, float] | None = None

    # ---- proprioception ---------------------------------------------------------------------

    @property
    def pose(self) -> tuple[float, float, float]:
        return tuple(float(v) for v in self.robot.pose)  # type: ignore[return-value]

    @property
    def clock(self) -> float:
        return float(self.robot.clock)

    @property
    def odometry(self) -> float:
        return float(self.robot.odometry)

    @property
    def camera_height(self) -> float:
        return float(self.robot.camera_view().origin[2])

    def body(self) -> RobotBody:
        """The robot's own dimensions, limits and speeds (its URDF and specs, not the world)."""
        m = self.robot.model
        t = m.time
        return RobotBody(
            name=m.name, footprint_radius=m.footprint_radius, holonomic=m.holonomic,
            camera_height=self.camera_height - self.robot.torso,
            torso=JointRange(m.torso.low, m.torso.high), pan=JointRange(m.pan.low, m.pan.high),
            tilt=JointRange(m.tilt.low, m.tilt.high), hfov=m.camera.hfov, vfov=m.camera.vfov,
            depth_range=m.camera.depth_range, detect_range=m.camera.detect_range,
            laser_range=m.laser.max_range, linear_speed=t.linear_speed,
            angular_speed=t.angular_speed, torso_speed=t.torso_speed, pan_speed=t.pan_speed,
            tilt_speed=t.tilt_speed, scan_time=t.scan_time, sensing_time=t.sensing_time,
            clearance=_CLEARANCE.get(m.name, PLANNING_CLEARANCE))

    # ---- acting -----------------------------------------------------------------------------

    def move_along(self, path: Sequence[tuple[float, float]]) -> bool:
        """Drive through waypoints; False (without moving) if the path is blocked. Then
        `last_contact` is the point (x, y) where the base's rim would have touched something
        (its own contact sense, like a bumper; never what it touched)."""
        self.last_contact = None
        try:
            self.robot.move_along(list(path))
        except PathBlockedError as exc:
            if exc.touch is not None:
                self.last_contact = exc.touch
            return False
        except MotionError:
            return False
        return True

    def turn_to(self, yaw: float) -> None:
        self.robot.turn_to(yaw)

    def set_torso(self, height: float) -> None:
        """Lift the torso (clipped to its range; a no-op on a robot without one)."""
        torso = self.robot.model.torso
        self.robot.set_torso(min(max(height, torso.low), torso.high))

    def look(self, pan: float, tilt: float) -> None:
        """Point the camera; angles are clipped to the head's limits."""
        model = self.robot.model
        self.robot.set_head(min(max(pan, model.pan.low), model.pan.high),
                            min(max(tilt, model.tilt.low), model.tilt.high))

    # ---- sensing ----------------------------------------------------------------------------

    def scan(self):  # noqa: ANN201 - a LaserScan (sensor data class of the simulator)
        return self.robot.scan()

    def depth(self, size: tuple[int, int] = (32, 24)):  # noqa: ANN201 - a DepthScan
        """A depth frame from the head camera (for the 3D map)."""
        return self.robot.depth(size)

    def detect(self, labels: Sequence[str]) -> list[Seen]:
        frame = self.robot.detect(list(labels))
        seen = []
        for d in frame.detections:
            sid = len(self.truth_of) + 1
            self.truth_of[sid] = d.truth_name
            seen.append(Seen(sid, d.label, tuple(float(v) for v in d.position), d.confidence))
        return seen

    def classify_place(self) -> str | None:
        try:
            return self.robot.classify_place().observed
        except SimError:
            return None


def load_spec(world: str | Path, robot: str | None = None, start: Sequence[float] | None = None,
              start_room: str | None = None, closed_doors: Sequence[int] = ()) -> WorldSpec:
    """The world spec with the robot model / start pose / door states the episode asks for."""
    try:
        spec = load_world_spec(world)
    except SimError as exc:
        raise EpisodeError(str(exc)) from exc
    return _with_robot(spec, robot, start, start_room, closed_doors)


GENERATE_KEYS = ("seed", "style", "rooms", "surprise", "day", "move", "doors", "table")


def generated_spec(generate: Mapping[str, Any], robot: str | None = None,
                   start: Sequence[float] | None = None,
                   start_room: str | None = None) -> WorldSpec:
    """A generated world (`{seed, style, rooms, surprise, day, move, doors, table}`, see
    `sim.generate`): `day` k > 0 is the building k days on, objects moved with probability
    `move` and doors toggled with probability `doors` each day; `table` names the placement
    table (`default`, or `moved`: sim/generation/placement-moved.yaml)."""
    try:
        world = generate_world_of(generate)
        spec = world.spec()
    except SimError as exc:
        raise EpisodeError(f"generate: {exc}") from exc
    return _with_robot(spec, robot, start, start_room, ())


def generate_world_of(generate: Mapping[str, Any]) -> Any:
    """`sim.generate.generate_world` of an episode's `generate` mapping (a `GeneratedWorld`);
    EpisodeError naming the key when a key is unknown or a value is not of its kind."""
    from sim.generate import DEFAULT_DOORS, DEFAULT_MOVE, generate_world
    from sim.generation.table import DEFAULT_TABLE, TABLES

    if not isinstance(generate, Mapping):
        raise EpisodeError(f"generate: expected a mapping of {', '.join(GENERATE_KEYS)}; "
                           f"got {generate!r}")
    unknown = set(generate) - set(GENERATE_KEYS)
    if unknown or "seed" not in generate:
        raise EpisodeError(f"generate: expected keys seed (required), style, rooms, surprise, "
                           f"day, move, doors, table; got {sorted(generate)}")
    day = generate.get("day", 0)
    if isinstance(day, bool) or not isinstance(day, int) or day < 0:
        raise EpisodeError(f"generate.day: expected an integer >= 0, got {day!r}")
    for key in ("move", "doors"):
        value = generate.get(key, 0.0)
        if isinstance(value, bool) or not isinstance(value, int | float) \
                or not 0.0 <= value <= 1.0:
            raise EpisodeError(f"generate.{key}: expected a probability in [0, 1], got "
                               f"{value!r}")
    table = generate.get("table", DEFAULT_TABLE)
    if not isinstance(table, str) or table not in TABLES:
        raise EpisodeError(f"generate.table: expected a placement table, one of "
                           f"{', '.join(TABLES)}; got {table!r}")
    try:
        return generate_world(int(generate["seed"]), str(generate.get("style", "office")),
                              generate.get("rooms"), float(generate.get("surprise", 0.25)),
                              day=day, move=float(generate.get("move", DEFAULT_MOVE)),
                              doors=float(generate.get("doors", DEFAULT_DOORS)), table=table)
    except (TypeError, ValueError) as exc:
        raise EpisodeError(f"generate: {exc}") from exc


def _with_robot(spec: WorldSpec, robot: str | None, start: Sequence[float] | None,
                start_room: str | None, closed_doors: Sequence[int]) -> WorldSpec:
    """The spec with the robot model, start pose and door states an episode asks for."""
    pose = tuple(spec.robot.start)
    if start_room is not None:
        room = spec.room(start_room)
        if room is None:
            raise EpisodeError(f"--start-room {start_room!r}: the world has rooms "
                               f"{', '.join(r.name for r in spec.rooms)}")
        pose = (*free_spot(spec, room, robot or spec.robot.model), 0.0)
    if start is not None:
        if len(start) != 3 or not all(math.isfinite(float(v)) for v in start):
            raise EpisodeError(f"start pose must be x,y,yaw (3 finite numbers), got {start!r}")
        pose = tuple(float(v) for v in start)
    robot_spec = dataclasses.replace(spec.robot, model=robot or spec.robot.model, start=pose)
    doors = list(spec.doors)
    for i in closed_doors:
        if not 0 <= i < len(doors):
            raise EpisodeError(f"closed door index {i}: the world has {len(doors)} doors")
        doors[i] = dataclasses.replace(doors[i], open=False)
    return dataclasses.replace(spec, robot=robot_spec, doors=tuple(doors))


def free_spot(spec: WorldSpec, room: RoomSpec, model: str,
              step: float = 0.25) -> tuple[float, float]:
    """The point nearest the room's centre where the robot's footprint touches nothing."""
    radius = ROBOT_MODELS[model].footprint_radius + 0.1 if model in ROBOT_MODELS else 0.5
    x0, y0, x1, y1 = room.rect
    cx, cy = room.center
    xs = [x0 + radius + spec.wall_thickness + k * step
          for k in range(int((x1 - x0) / step) + 1)]
    ys = [y0 + radius + spec.wall_thickness + k * step
          for k in range(int((y1 - y0) / step) + 1)]
    spots = sorted(((x, y) for x in xs for y in ys
                    if x <= x1 - radius - spec.wall_thickness
                    and y <= y1 - radius - spec.wall_thickness),
                   key=lambda p: math.dist(p, (cx, cy)))
    boxes = [MplPath(f.footprint()) for f in spec.furniture]
    for spot in spots:
        if not any(box.contains_point(spot, radius=2 * radius) or
                   box.contains_point(spot, radius=-2 * radius) for box in boxes):
            return spot
    raise EpisodeError(f"room {room.name!r} has no spot free for the robot to start in")


def check_categories(spec: WorldSpec, known: Sequence[str]) -> None:
    """Every room's category must be one of the conceptual map's (`known`), else the robot's
    readings there could not be used; the error names the room and the known categories."""
    for i, room in enumerate(spec.rooms):
        if room.category not in known:
            raise EpisodeError(f"{spec.source}: rooms[{i}] ({room.name}): category "
                               f"{room.category!r} is not in the knowledge base (known: "
                               f"{', '.join(known)}; case, spaces and hyphens do not matter)")


def open_world(spec: WorldSpec, seed: int, categories: Sequence[str] | None = None
               ) -> SimRobot:
    """Build the PyBullet world (close it with `robot.world.close()`); the place classifier
    confuses among `categories` (the conceptual map's vocabulary), not the building's."""
    try:
        return SimRobot(World(spec, seed, categories))
    except SimError as exc:
        raise EpisodeError(str(exc)) from exc
