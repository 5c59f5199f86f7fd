"""The robot adapter: pose, collision-checked kinematic motion, joints, sensors, a sim clock.

Motion is kinematic (poses are set, not simulated), checked against walls, doors, furniture and
floor objects with the base's footprint cylinder, and charged to `clock` by the robot's
`TimeModel`. A refused request raises a `MotionError` and changes nothing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from sim.camera import DetectorConfig, depth_frame, detect_objects
from sim.errors import JointLimitError, MotionError, PathBlockedError, SimError, WorldFileError
from sim.laser import laser_scan
from sim.place_classifier import DEFAULT_CATEGORIES, PlaceClassifier
from sim.robot_models import ROBOT_MODELS, Limits, RobotModel
from sim.scene import ROBOT_GROUP, WORLD_GROUP
from sim.sensor_data import CameraView, DepthScan, DetectionFrame, LaserScan, PlaceObservation
from sim.time_model import wrap_angle

if TYPE_CHECKING:
    from sim.scene import World

COLLISION_STEP = 0.05  # metres between footprint checks along a path
_PENETRATION = 1e-4  # contacts deeper than this are collisions; touching is allowed


@dataclass(frozen=True)
class MotionResult:
    """What a motion call did: simulated seconds spent, metres driven, the pose at the end."""

    duration: float
    distance: float
    pose: tuple[float, float, float]


class Robot:
    """A robot standing in a `World`; every call advances `clock` (simulated seconds)."""

    def __init__(self, world: World, model: str, start: Sequence[float],
                 categories: Sequence[str] | None = None):
        if model not in ROBOT_MODELS:
            raise SimError(f"unknown robot model {model!r} (known: {', '.join(ROBOT_MODELS)})")
        self.world = world
        self.model: RobotModel = ROBOT_MODELS[model]
        self.clock = 0.0
        self.odometry = 0.0
        self.detector_config = DetectorConfig()
        self.place_classifier = _classifier(world, categories)
        self._rng = world.rng(f"robot-{model}-sensors")
        self._pose = (float(start[0]), float(start[1]), float(start[2]))
        self._torso = self._pan = self._tilt = 0.0
        self._touch: tuple[float, float] | None = None  # where the base last touched something
        self._load_body()
        blocker = self._collision_at(self._pose)
        if blocker is not None:
            raise WorldFileError(f"{world.spec.source}: robot.start ({start[0]:g}, {start[1]:g}): "
                                 f"the {model} footprint (radius {self.model.footprint_radius:g} "
                                 f"m) collides with {blocker}")

    # --- state -------------------------------------------------------------------------
    @property
    def pose(self) -> tuple[float, float, float]:
        """Base pose (x, y, yaw) in the world."""
        return self._pose

    @property
    def torso(self) -> float:
        return self._torso

    @property
    def head(self) -> tuple[float, float]:
        """(pan, tilt) in radians; positive tilt looks up."""
        return (self._pan, self._tilt)

    def room(self) -> str | None:
        """Name of the room the base stands in (ground truth, for the simulator's own use)."""
        room = self.world.spec.room_at(self._pose[0], self._pose[1])
        return room.name if room is not None else None

    # --- motion ------------------------------------------------------------------------
    def move_along(self, path: Sequence[Sequence[float]]) -> MotionResult:
        """Drive through waypoints (x, y); refuse the whole path if any part is blocked."""
        points = [_waypoint(p, i) for i, p in enumerate(path)]
        self._check_path(points)
        duration = self.model.time.path(self._pose, points, self.model.holonomic)
        x, y, yaw = self._pose
        distance = 0.0
        for px, py in points:
            step = math.hypot(px - x, py - y)
            if step > 1e-9 and not self.model.holonomic:
                yaw = math.atan2(py - y, px - x)
            distance += step
            x, y = px, py
        self._set_pose((x, y, yaw))
        self.odometry += distance
        return self._spend(duration, distance)

    def blocked_by(self, path: Sequence[Sequence[float]]) -> str | None:
        """Why `move_along(path)` would be refused (a message), or None if it is free."""
        try:
            self._check_path([_waypoint(p, i) for i, p in enumerate(path)])
        except PathBlockedError as exc:
            return str(exc)
        return None

    def turn_to(self, yaw: float) -> MotionResult:
        """Turn in place to heading `yaw` the short way round."""
        if not math.isfinite(yaw):
            raise MotionError(f"turn_to: yaw must be finite, got {yaw}")
        duration = self.model.time.turn(yaw - self._pose[2])
        self._set_pose((self._pose[0], self._pose[1], wrap_angle(yaw)))
        return self._spend(duration, 0.0)

    def set_torso(self, height: float) -> MotionResult:
        """Move the torso lift to `height` metres within its limits."""
        _check_limit("torso", height, self.model.torso, "m")
        duration = self.model.time.torso(height - self._torso)
        self._torso = float(height)
        self._apply_joints()
        return self._spend(duration, 0.0)

    def set_head(self, pan: float, tilt: float) -> MotionResult:
        """Point the head (radians; positive tilt looks up) within its joint limits."""
        _check_limit("pan", pan, self.model.pan, "rad")
        _check_limit("tilt", tilt, self.model.tilt, "rad")
        duration = self.model.time.head(pan - self._pan, tilt - self._tilt)
        self._pan, self._tilt = float(pan), float(tilt)
        self._apply_joints()
        return self._spend(duration, 0.0)

    def wait(self, seconds: float) -> None:
        """Let simulated time pass without doing anything."""
        if not seconds >= 0:
            raise MotionError(f"wait: seconds must be >= 0, got {seconds}")
        self.clock += seconds

    # --- sensing -----------------------------------------------------------------------
    def scan(self) -> LaserScan:
        """One laser scan (costs `scan_time`)."""
        self.clock += self.model.time.scan_time
        position, yaw = self._link_pose(self._laser_link)
        return laser_scan(self.world.client, (position[0], position[1], yaw), position[2],
                          self.model.laser, self._rng, self.clock)

    def camera_view(self, max_range: float | None = None) -> CameraView:
        """Where the camera looks now (defaults to the recognition range)."""
        position, _ = self._link_pose(self._camera_link)
        forward = self._link_forward(self._camera_link)
        cam = self.model.camera
        return CameraView(origin=position, yaw=math.atan2(forward[1], forward[0]),
                          pitch=math.asin(max(-1.0, min(1.0, forward[2]))), hfov=cam.hfov,
                          vfov=cam.vfov, max_range=max_range or cam.detect_range)

    def depth(self, size: tuple[int, int] = (32, 24)) -> DepthScan:
        """Depth rays over a (columns, rows) grid of the camera image (costs `scan_time`)."""
        self.clock += self.model.time.scan_time
        view = self.camera_view(self.model.camera.depth_range)
        return depth_frame(self.world.client, view, size, self.model.camera.depth_noise_sigma,
                           self._rng, self.clock)

    def detect(self, labels: Sequence[str] | None = None) -> DetectionFrame:
        """Recognise objects (of `labels`, or any) in the camera view (costs `sensing_time`)."""
        if isinstance(labels, str):
            labels = [labels]
        self.clock += self.model.time.sensing_time
        return detect_objects(self.world.client, self.camera_view(), self.world.detectables,
                              self.detector_config, self._rng, self.clock, labels)

    def classify_place(self) -> PlaceObservation:
        """Noisy category of the current room (costs `sensing_time`)."""
        room = self.world.spec.room_at(self._pose[0], self._pose[1])
        if room is None:
            raise SimError(f"classify_place: robot at {self._pose[:2]} is outside every room")
        self.clock += self.model.time.sensing_time
        return self.place_classifier.observe(room.category, self._rng, self.clock)

    # --- internals ---------------------------------------------------------------------
    def _spend(self, duration: float, distance: float) -> MotionResult:
        self.clock += duration
        return MotionResult(duration=duration, distance=distance, pose=self._pose)

    def _load_body(self) -> None:
        client = self.world.client
        self.body = client.loadURDF(str(self.model.urdf), [0, 0, 0], useFixedBase=True)
        self._joints: dict[str, int] = {}
        self._links: dict[str, int] = {}
        for j in range(client.getNumJoints(self.body)):
            info = client.getJointInfo(self.body, j)
            self._joints[info[1].decode()] = j
            self._links[info[12].decode()] = j
        for link in [-1, *self._links.values()]:
            client.setCollisionFilterGroupMask(self.body, link, ROBOT_GROUP, WORLD_GROUP)
        self._laser_link = self._links["laser_link"]
        self._camera_link = self._links["camera_link"]
        self._set_pose(self._pose)
        self._apply_joints()

    def _apply_joints(self) -> None:
        names = {"pan": ("pan_joint", "head_pan_joint"), "tilt": ("tilt_joint", "head_tilt_joint"),
                 "torso": ("torso_lift_joint",)}
        values = {"pan": self._pan, "tilt": self._tilt, "torso": self._torso}
        for key, candidates in names.items():
            for name in candidates:
                if name in self._joints:
                    self.world.client.resetJointState(self.body, self._joints[name], values[key])

    def _set_pose(self, pose: tuple[float, float, float]) -> None:
        self._pose = (pose[0], pose[1], wrap_angle(pose[2]))
        quat = self.world.client.getQuaternionFromEuler([0.0, 0.0, self._pose[2]])
        self.world.client.resetBasePositionAndOrientation(self.body, [pose[0], pose[1], 0.0], quat)

    def _collision_at(self, pose: tuple[float, float, float]) -> str | None:
        """Name of what the footprint would hit at `pose`, or None (leaves the robot there)."""
        self._set_pose(pose)
        client = self.world.client
        client.performCollisionDetection()
        for contact in client.getContactPoints(bodyA=self.body):
            if contact[8] < -_PENETRATION:
                self._touch = (float(contact[5][0]), float(contact[5][1]))  # on the base
                return self.world.body_name(contact[2])
        return None

    def _check_path(self, points: list[tuple[float, float]]) -> None:
        start = self._pose
        try:
            x, y = start[0], start[1]
            for i, (px, py) in enumerate(points):
                length = math.hypot(px - x, py - y)
                for t in np.linspace(0.0, 1.0, max(2, math.ceil(length / COLLISION_STEP) + 1)):
                    cx, cy = x + t * (px - x), y + t * (py - y)
                    blocker = self._collision_at((cx, cy, start[2]))
                    if blocker is not None:
                        raise PathBlockedError(
                            f"move_along: segment {i} from ({x:.2f}, {y:.2f}) to ({px:.2f}, "
                            f"{py:.2f}) is blocked at ({cx:.2f}, {cy:.2f}) by {blocker} "
                            f"(footprint radius {self.model.footprint_radius:g} m); not moved",
                            at=(float(cx), float(cy)), heading=math.atan2(py - y, px - x),
                            touch=self._touch)
                x, y = px, py
        finally:
            self._set_pose(start)

    def _link_pose(self, link: int) -> tuple[np.ndarray, float]:
        state = self.world.client.getLinkState(self.body, link, computeForwardKinematics=True)
        forward = self._link_forward(link)
        return np.array(state[4], dtype=float), math.atan2(forward[1], forward[0])

    def _link_forward(self, link: int) -> np.ndarray:
        state = self.world.client.getLinkState(self.body, link, computeForwardKinematics=True)
        matrix = np.array(self.world.client.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        return matrix[:, 0]


def _classifier(world: World, categories: Sequence[str] | None) -> PlaceClassifier:
    """A classifier that confuses among `categories` (its own default vocabulary when None);
    every room of the world must have a category it knows."""
    known = tuple(categories) if categories is not None else DEFAULT_CATEGORIES
    for i, room in enumerate(world.spec.rooms):
        if room.category not in known:
            raise WorldFileError(f"{world.spec.source}: rooms[{i}] ({room.name}): category "
                                 f"{room.category!r} is not one the place classifier knows "
                                 f"({', '.join(known)})")
    return PlaceClassifier.with_accuracy(known)


def _waypoint(point: Sequence[float], index: int) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in point)
    except (TypeError, ValueError):
        raise MotionError(f"move_along: waypoint {index} must be (x, y), got {point!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise MotionError(f"move_along: waypoint {index} must be finite, got {point!r}")
    return (x, y)


def _check_limit(joint: str, value: float, limits: Limits, unit: str) -> None:
    if not math.isfinite(value) or not limits.contains(value):
        raise JointLimitError(f"{joint} {value:g} {unit} is outside the limits "
                              f"[{limits.low:g}, {limits.high:g}] {unit}; not moved")
