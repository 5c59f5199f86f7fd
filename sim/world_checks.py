"""Geometric validation of a parsed world: every impossible thing is an error naming its entry.

Checked: unique names, rooms inside the world and not overlapping, doors on the wall two rooms
share, furniture inside its room clear of the walls and of other furniture, objects on a
furniture top or inside a room.
"""

from __future__ import annotations

import math

from sim.errors import WorldFileError
from sim.world_spec import DoorSpec, FurnitureSpec, ObjectSpec, RoomSpec, WorldSpec, box_corners

_EPS = 1e-6
_ON_WALL_TOLERANCE = 0.02  # metres a door centre may sit off the wall line


def check_world(spec: WorldSpec) -> None:
    """Raise `WorldFileError` for the first impossible entry of `spec`."""
    _check_names(spec)
    for i, room in enumerate(spec.rooms):
        _check_room(spec, i, room)
    for i, door in enumerate(spec.doors):
        _check_door(spec, i, door)
    for i, item in enumerate(spec.furniture):
        _check_furniture(spec, i, item)
    for i, obj in enumerate(spec.objects):
        _check_object(spec, i, obj)
    _check_robot(spec)


def _fail(spec: WorldSpec, where: str, message: str) -> WorldFileError:
    return WorldFileError(f"{spec.source}: {where}: {message}")


def _check_names(spec: WorldSpec) -> None:
    seen: dict[str, str] = {}
    entries = [("rooms", r.name) for r in spec.rooms] + [
        ("furniture", f.name) for f in spec.furniture] + [("objects", o.name) for o in spec.objects]
    counters: dict[str, int] = {}
    for kind, name in entries:
        index = counters.get(kind, 0)
        counters[kind] = index + 1
        where = f"{kind}[{index}] ({name})"
        if name in seen:
            raise _fail(spec, where, f"name {name!r} is already used by {seen[name]}")
        seen[name] = where


def _check_room(spec: WorldSpec, i: int, room: RoomSpec) -> None:
    where = f"rooms[{i}] ({room.name})"
    x0, y0, x1, y1 = room.rect
    if x1 - x0 <= _EPS or y1 - y0 <= _EPS:
        raise _fail(spec, where, f"rect {list(room.rect)} must have x0 < x1 and y0 < y1")
    w, h = spec.size
    if x0 < -_EPS or y0 < -_EPS or x1 > w + _EPS or y1 > h + _EPS:
        raise _fail(spec, where, f"rect {list(room.rect)} leaves the world (size {w} x {h})")
    for other in spec.rooms[:i]:
        ox0, oy0, ox1, oy1 = other.rect
        overlap_x = min(x1, ox1) - max(x0, ox0)
        overlap_y = min(y1, oy1) - max(y0, oy0)
        if overlap_x > _EPS and overlap_y > _EPS:
            raise _fail(spec, where, f"overlaps room {other.name} "
                        f"(by {overlap_x:.2f} x {overlap_y:.2f} m)")


def shared_wall(a: RoomSpec, b: RoomSpec) -> tuple[str, float, float, float] | None:
    """The border two rooms share as (axis, line, lo, hi): axis 'x' means the line x = const."""
    ax0, ay0, ax1, ay1 = a.rect
    bx0, by0, bx1, by1 = b.rect
    for line_a, line_b in ((ax1, bx0), (ax0, bx1)):
        lo, hi = max(ay0, by0), min(ay1, by1)
        if abs(line_a - line_b) < _EPS and hi - lo > _EPS:
            return ("x", line_a, lo, hi)
    for line_a, line_b in ((ay1, by0), (ay0, by1)):
        lo, hi = max(ax0, bx0), min(ax1, bx1)
        if abs(line_a - line_b) < _EPS and hi - lo > _EPS:
            return ("y", line_a, lo, hi)
    return None


def _check_door(spec: WorldSpec, i: int, door: DoorSpec) -> None:
    where = f"doors[{i}] ({door.label})"
    rooms = [spec.room(name) for name in door.rooms]
    for name, room in zip(door.rooms, rooms, strict=True):
        if room is None:
            raise _fail(spec, where, f"no room named {name!r}")
    a, b = rooms
    assert a is not None and b is not None
    if a.name == b.name:
        raise _fail(spec, where, "a door needs two different rooms")
    wall = shared_wall(a, b)
    if wall is None:
        raise _fail(spec, where, f"rooms {a.name} and {b.name} share no wall")
    axis, line, lo, hi = wall
    across, along = (door.at[0], door.at[1]) if axis == "x" else (door.at[1], door.at[0])
    other = "y" if axis == "x" else "x"
    wall_text = f"{axis} = {line:g}, {other} in [{lo:g}, {hi:g}]"
    if abs(across - line) > _ON_WALL_TOLERANCE or not lo <= along <= hi:
        raise _fail(spec, where, f"door at ({door.at[0]:g}, {door.at[1]:g}) is not on the "
                    f"shared wall of {a.name} and {b.name} ({wall_text})")
    half = door.width / 2.0
    if along - half < lo - _EPS or along + half > hi + _EPS:
        raise _fail(spec, where, f"door of width {door.width:g} at ({door.at[0]:g}, "
                    f"{door.at[1]:g}) does not fit in the shared wall ({wall_text})")


def _check_furniture(spec: WorldSpec, i: int, item: FurnitureSpec) -> None:
    where = f"furniture[{i}] ({item.name})"
    room = spec.room(item.room)
    if room is None:
        raise _fail(spec, where, f"no room named {item.room!r}")
    margin = spec.wall_thickness / 2.0
    for x, y in item.footprint():
        if not room.contains(x, y):
            raise _fail(spec, where, f"corner ({x:.2f}, {y:.2f}) is outside its room {room.name}")
        if not room.contains(x, y, margin - _EPS):
            raise _fail(spec, where, f"overlaps a wall of room {room.name}: corner "
                        f"({x:.2f}, {y:.2f}) is within {margin:g} m of the border")
    for other in spec.furniture[:i]:
        if _footprints_overlap(item.footprint(), other.footprint()):
            raise _fail(spec, where, f"overlaps furniture {other.name}")
    if item.size[2] >= spec.wall_height:
        raise _fail(spec, where, f"height {item.size[2]:g} reaches the ceiling "
                    f"(wall_height {spec.wall_height:g})")


def _footprints_overlap(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> bool:
    """Separating-axis test of two convex quadrilaterals (touching does not count)."""
    for poly in (a, b):
        for k in range(len(poly)):
            (x0, y0), (x1, y1) = poly[k], poly[(k + 1) % len(poly)]
            nx, ny = y0 - y1, x1 - x0
            pa = [nx * x + ny * y for x, y in a]
            pb = [nx * x + ny * y for x, y in b]
            if max(pa) <= min(pb) + _EPS or max(pb) <= min(pa) + _EPS:
                return False
    return True


def _check_object(spec: WorldSpec, i: int, obj: ObjectSpec) -> None:
    where = f"objects[{i}] ({obj.name})"
    if obj.on is not None:
        _check_object_on(spec, where, obj)
        return
    assert obj.pose is not None
    x, y, _ = obj.pose
    margin = spec.wall_thickness / 2.0 + max(obj.size[0], obj.size[1]) / 2.0
    if spec.room_at(x, y) is None:
        raise _fail(spec, where, f"pose ({x:g}, {y:g}) is outside every room")
    if not any(r.contains(x, y, margin - _EPS) for r in spec.rooms):
        raise _fail(spec, where, f"pose ({x:g}, {y:g}) puts the object into a wall")
    for item in spec.furniture:
        _check_object_vs_furniture(spec, where, obj, item)


def _check_object_on(spec: WorldSpec, where: str, obj: ObjectSpec) -> None:
    support = spec.furniture_named(obj.on or "")
    if support is None:
        raise _fail(spec, where, f"'on': no furniture named {obj.on!r}")
    dx, dy, _ = obj.offset
    hx, hy = support.size[0] / 2.0, support.size[1] / 2.0
    if abs(dx) > hx + _EPS or abs(dy) > hy + _EPS:
        raise _fail(spec, where, f"floating: offset ({dx:g}, {dy:g}) is off the top of "
                    f"{support.name} (half-extents {hx:g} x {hy:g})")


def _check_object_vs_furniture(spec: WorldSpec, where: str, obj: ObjectSpec,
                               item: FurnitureSpec) -> None:
    """A floor object is either clear of a furniture box or wholly inside it (a closed cabinet)."""
    assert obj.pose is not None
    corners = box_corners(obj.pose, (obj.size[0], obj.size[1]))
    inside = [_in_box(item, x, y) for x, y in corners]
    if all(inside) and obj.size[2] < item.size[2]:
        return
    if any(inside) or _in_box(item, obj.pose[0], obj.pose[1]):
        raise _fail(spec, where, f"intersects furniture {item.name} (an object on the floor "
                    "must be clear of it or wholly inside it)")


def _in_box(item: FurnitureSpec, x: float, y: float) -> bool:
    fx, fy, yaw = item.pose
    c, s = math.cos(yaw), math.sin(yaw)
    u, v = c * (x - fx) + s * (y - fy), -s * (x - fx) + c * (y - fy)
    return abs(u) < item.size[0] / 2.0 and abs(v) < item.size[1] / 2.0


def _check_robot(spec: WorldSpec) -> None:
    x, y, _ = spec.robot.start
    if spec.room_at(x, y) is None:
        raise _fail(spec, "robot.start", f"({x:g}, {y:g}) is outside every room")
