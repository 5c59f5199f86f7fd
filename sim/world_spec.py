"""The parsed, immutable description of a world (what a world file says, before any physics).

Loading and checking live in `world_file` and `world_checks`; this module only holds the values
and the small geometric facts derived from them (footprints, object placements).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Rect = tuple[float, float, float, float]


def normalise_category(name: str) -> str:
    """One spelling per room category: case, spaces and hyphens do not matter
    (`Meeting room` = `meeting-room` = `meeting_room`)."""
    return "_".join(name.strip().lower().replace("-", " ").split())


@dataclass(frozen=True)
class RoomSpec:
    """An axis-aligned room; walls are built on its border."""

    name: str
    category: str
    rect: Rect  # x0, y0, x1, y1

    def contains(self, x: float, y: float, margin: float = 0.0) -> bool:
        """Whether (x, y) lies inside the rectangle shrunk by `margin` (borders included)."""
        x0, y0, x1, y1 = self.rect
        return x0 + margin <= x <= x1 - margin and y0 + margin <= y <= y1 - margin

    @property
    def center(self) -> Vec2:
        x0, y0, x1, y1 = self.rect
        return ((x0 + x1) / 2.0, (y0 + y1) / 2.0)


@dataclass(frozen=True)
class DoorSpec:
    """An opening of `width` centred at `at` in the wall shared by two rooms."""

    rooms: tuple[str, str]
    at: Vec2
    width: float
    open: bool = True

    @property
    def label(self) -> str:
        return f"{self.rooms[0]}/{self.rooms[1]}"


@dataclass(frozen=True)
class FurnitureSpec:
    """A box standing on the floor; its top is a supporting surface."""

    name: str
    label: str
    room: str
    pose: Vec3  # x, y, yaw of the box centre
    size: Vec3  # extent along its own x, y, and height

    def footprint(self) -> list[Vec2]:
        """The four floor corners, counter-clockwise."""
        return box_corners(self.pose, (self.size[0], self.size[1]))


@dataclass(frozen=True)
class ObjectSpec:
    """A small detectable thing: on a furniture top (`on` + `offset`) or on the floor (`pose`)."""

    name: str
    label: str
    size: Vec3
    on: str | None = None
    offset: Vec3 = (0.0, 0.0, 0.0)  # dx, dy, dyaw in the furniture's frame
    pose: Vec3 | None = None  # x, y, yaw on the floor


@dataclass(frozen=True)
class RobotSpec:
    """Which robot model starts where."""

    model: str
    start: Vec3  # x, y, yaw


@dataclass(frozen=True)
class WorldSpec:
    """A whole world file, parsed; `source` names the file in error messages."""

    name: str
    size: Vec2
    wall_height: float
    rooms: tuple[RoomSpec, ...]
    doors: tuple[DoorSpec, ...]
    furniture: tuple[FurnitureSpec, ...]
    objects: tuple[ObjectSpec, ...]
    robot: RobotSpec
    source: str = "<world>"
    wall_thickness: float = 0.1

    def room(self, name: str) -> RoomSpec | None:
        return next((r for r in self.rooms if r.name == name), None)

    def furniture_named(self, name: str) -> FurnitureSpec | None:
        return next((f for f in self.furniture if f.name == name), None)

    def room_at(self, x: float, y: float) -> RoomSpec | None:
        """The first room whose rectangle contains (x, y), or None outside every room."""
        return next((r for r in self.rooms if r.contains(x, y)), None)

    def object_pose(self, obj: ObjectSpec) -> tuple[float, float, float, float]:
        """World placement (x, y, z_bottom, yaw) of an object: on its furniture top or the floor."""
        if obj.on is None:
            assert obj.pose is not None
            return (obj.pose[0], obj.pose[1], 0.0, obj.pose[2])
        support = self.furniture_named(obj.on)
        assert support is not None, f"unchecked world: no furniture {obj.on}"
        fx, fy, fyaw = support.pose
        dx, dy, dyaw = obj.offset
        c, s = math.cos(fyaw), math.sin(fyaw)
        return (fx + c * dx - s * dy, fy + s * dx + c * dy, support.size[2], fyaw + dyaw)


def box_corners(pose: Vec3, size: Vec2) -> list[Vec2]:
    """Corners of a rectangle of `size` centred at pose (x, y, yaw), counter-clockwise."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2.0, size[1] / 2.0
    local = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
    return [(x + c * u - s * v, y + s * u + c * v) for u, v in local]
