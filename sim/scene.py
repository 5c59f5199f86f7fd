"""A world in PyBullet: floor, walls with door openings, doors, furniture, objects, one robot.

Every `World` owns its own `BulletClient` in DIRECT mode (never the global client), so several
worlds live side by side in one process. Randomness comes from named streams of one seed.
"""

from __future__ import annotations

import contextlib
import os
import sys
import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from sim.walls import DoorOpening, WallSegment, door_openings, wall_segments
from sim.world_file import load_world_spec
from sim.world_spec import WorldSpec

# Collision groups: rays (group 1) see only world bodies; the robot collides only with those.
WORLD_GROUP = 1
ROBOT_GROUP = 2
_PARKED_Z = -50.0  # where open doors wait, out of every ray's way
_DOOR_THICKNESS = 0.04


@dataclass(frozen=True)
class Detectable:
    """A furniture piece or object the semantic camera can recognise (ground truth)."""

    name: str
    label: str
    body: int
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    yaw: float


class World:
    """A loaded world: its spec, physics client, bodies, and seeded random streams."""

    def __init__(self, spec: WorldSpec, seed: int = 0,
                 categories: Sequence[str] | None = None):
        """`categories`: the place classifier's vocabulary (its default when None)."""
        from sim.robot import Robot  # the robot adapter needs a built world to stand in

        self.spec = spec
        self.seed = seed
        self.client = _connect()
        self.walls: list[WallSegment] = wall_segments(spec)
        self.doors: list[DoorOpening] = door_openings(spec)
        self._door_open = [d.open for d in self.doors]
        self._names: dict[int, str] = {}
        self.detectables: list[Detectable] = []
        try:
            self._build()
            self.robot = Robot(self, spec.robot.model, spec.robot.start, categories)
        except BaseException:
            self.close()  # a refused world must not leak its physics client
            raise

    def rng(self, stream: str) -> np.random.Generator:
        """A generator for one named purpose, determined by the world's seed and the name."""
        return np.random.default_rng([self.seed, zlib.crc32(stream.encode())])

    def body_name(self, body: int) -> str:
        """Name of a static body (a wall, door, furniture piece or object), for messages."""
        return self._names.get(body, f"body {body}")

    def door_is_open(self, index: int) -> bool:
        return self._door_open[index]

    def set_door_open(self, index: int, is_open: bool) -> None:
        """Open or close door `index` (file order); a closed door blocks motion and sensing."""
        opening = self.doors[index]
        body = self._door_bodies[index]
        self.client.resetBasePositionAndOrientation(
            body, _door_position(opening, self.spec.wall_height, is_open), [0, 0, 0, 1])
        self._door_open[index] = is_open

    def close(self) -> None:
        """Disconnect the physics client; the world is unusable afterwards."""
        if self.client is not None:
            self.client.disconnect()
            self.client = None  # type: ignore[assignment]

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _build(self) -> None:
        w, h = self.spec.size
        self._static_box("floor", (w / 2, h / 2, -0.05), (w + 1.0, h + 1.0, 0.1), 0.0)
        t = self.spec.wall_thickness
        door_edges = {(d.segment.axis, round(d.segment.line, 6), round(v, 6))
                      for d in self.doors for v in (d.segment.lo, d.segment.hi)}
        for seg in self.walls:
            # close the corners by t/2 at each end, but never narrow a door opening
            lo = seg.lo - (0 if (seg.axis, round(seg.line, 6), round(seg.lo, 6)) in door_edges
                           else t / 2)
            hi = seg.hi + (0 if (seg.axis, round(seg.line, 6), round(seg.hi, 6)) in door_edges
                           else t / 2)
            length, mid = hi - lo, (lo + hi) / 2
            center = (seg.line, mid) if seg.axis == "x" else (mid, seg.line)
            size = (t, length) if seg.axis == "x" else (length, t)
            name = f"wall {seg.axis}={seg.line:g} [{seg.lo:g}, {seg.hi:g}]"
            self._static_box(name, (*center, self.spec.wall_height / 2),
                             (*size, self.spec.wall_height), 0.0)
        self._door_bodies = [self._door_body(opening) for opening in self.doors]
        for item in self.spec.furniture:
            x, y, yaw = item.pose
            center = (x, y, item.size[2] / 2)
            body = self._static_box(item.name, center, item.size, yaw)
            self.detectables.append(Detectable(item.name, item.label, body, center, item.size, yaw))
        for obj in self.spec.objects:
            x, y, z, yaw = self.spec.object_pose(obj)
            center = (x, y, z + obj.size[2] / 2)
            body = self._static_box(obj.name, center, obj.size, yaw)
            self.detectables.append(Detectable(obj.name, obj.label, body, center, obj.size, yaw))

    def _door_body(self, opening: DoorOpening) -> int:
        seg = opening.segment
        width = seg.hi - seg.lo
        size = (_DOOR_THICKNESS, width) if seg.axis == "x" else (width, _DOOR_THICKNESS)
        door = self.spec.doors[opening.index]
        body = self._static_box(f"closed door {opening.index} ({door.label})", (0.0, 0.0, 0.0),
                                (*size, self.spec.wall_height), 0.0)
        self.client.resetBasePositionAndOrientation(
            body, _door_position(opening, self.spec.wall_height, opening.open), [0, 0, 0, 1])
        return body

    def _static_box(self, name: str, center: tuple[float, ...], size: tuple[float, ...],
                    yaw: float) -> int:
        half = [s / 2 for s in size]
        shape = self.client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
        orientation = self.client.getQuaternionFromEuler([0.0, 0.0, yaw])
        body = self.client.createMultiBody(0.0, shape, -1, list(center), orientation)
        self.client.setCollisionFilterGroupMask(body, -1, WORLD_GROUP, WORLD_GROUP | ROBOT_GROUP)
        self._names[body] = name
        return body


def load_world(source: str | Path, seed: int = 0) -> World:
    """Load a built-in world by name (e.g. `office`) or a world file path, seeded."""
    return World(load_world_spec(source), seed)


def _door_position(opening: DoorOpening, wall_height: float,
                   is_open: bool) -> tuple[float, float, float]:
    seg = opening.segment
    mid = (seg.lo + seg.hi) / 2
    x, y = (seg.line, mid) if seg.axis == "x" else (mid, seg.line)
    return (x, y, _PARKED_Z if is_open else wall_height / 2)


def _connect() -> BulletClient:
    with _quiet_stdout():
        return BulletClient(connection_mode=pybullet.DIRECT)


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Silence the C library's banner on fd 1 while connecting (it would pollute CLI output)."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):
        yield
        return
    sys.stdout.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), fd)
            yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)
