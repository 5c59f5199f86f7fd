"""Blocked moves as evidence, and openings too narrow for the robot's body.

A move the base refuses (`SimRobot.last_contact`: the point of its rim that touched something)
becomes a `Blockage`: a keep-out disc for the robot's centre around the touched point (the
planning radius plus a margin that grows with each touch nearby) that the grid's
traversability (so every path, reachability and standpoint query) respects until
`retry_after` simulated seconds have passed, and that cuts the place-graph edges through it.
A blockage at a mapped door names the door. `narrow_openings` finds free space the robot can
see but not reach because an opening on the way is narrower than it squeezes through (at
that route's bottleneck, on the widest route there): the reason an episode gives when that is
all that is left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from conceptual_map.metric import OccupancyGrid, plan_path
from conceptual_map.metric.errors import PathQueryError
from conceptual_map.places.frontiers import reachable_mask
from conceptual_map.places.model import Door

Point = tuple[float, float]


@dataclass(frozen=True)
class Blockage:
    """Where a motion was refused: a keep-out disc, since when, until when, at which door."""

    id: str
    centre: Point
    radius: float
    time: float
    until: float
    door: str | None = None
    door_width: float | None = None

    def describe(self) -> str:
        where = f"({self.centre[0]:.2f}, {self.centre[1]:.2f})"
        if self.door is not None:
            return (f"the base touched door {self.door} ({self.door_width:.2f} m wide) at "
                    f"{where} at t={self.time:.0f} s")
        return f"the base touched something unmapped at {where} at t={self.time:.0f} s"

    def cuts(self, a: Point, b: Point, margin: float = 0.0) -> bool:
        """The straight segment a-b passes within `radius + margin` of the centre."""
        p, q, c = np.asarray(a), np.asarray(b), np.asarray(self.centre)
        d = q - p
        t = 0.0 if not d.any() else float(np.clip((c - p) @ d / (d @ d), 0.0, 1.0))
        return float(np.linalg.norm(p + t * d - c)) <= self.radius + margin


@dataclass
class Blockages:
    """The blockages the robot has run into; expired ones are forgotten."""

    retry_after: float = 300.0  # s of simulated time before a blocked spot is tried again
    margin: float = 0.05  # m beyond the planning radius kept from a touched point
    merge: float = 0.3  # m: touches this close are the same spot (each widens the berth)
    door_reach: float = 0.7  # m: a touch this near a mapped door's centre is at the door
    items: dict[str, Blockage] = field(default_factory=dict)  # active
    seen: dict[str, Blockage] = field(default_factory=dict)  # every touch, never forgotten
    _count: int = 0

    def add(self, touch: Point, time: float, doors: dict[str, Door],
            planning_radius: float) -> Blockage:
        """The base's rim touched something at `touch`: the robot's centre keeps
        `planning_radius` plus `margin` from there (a grid obstacle the scans missed, or a
        mapped one a few cm off), `margin` more for each blockage already near it."""
        near = sum(1 for b in self.seen.values() if math.dist(b.centre, touch) < self.merge)
        radius = planning_radius + self.margin * (1 + near)
        door = min(doors.values(), key=lambda d: math.dist(d.centre, touch), default=None)
        if door is not None and math.dist(door.centre, touch) > self.door_reach:
            door = None
        self._count += 1
        blockage = Blockage(f"blocked{self._count}", (float(touch[0]), float(touch[1])), radius,
                            time, time + self.retry_after, door.id if door else None,
                            door.width if door else None)
        self.items[blockage.id] = blockage
        self.seen[blockage.id] = blockage
        return blockage

    def clear(self) -> list[Blockage]:
        """Nothing else is left to try: every blocked spot is tried again (a spot touched
        again gets a wider berth, so retrying ends)."""
        gone = list(self.items.values())
        self.items.clear()
        return gone

    def expire(self, time: float) -> list[Blockage]:
        gone = [b for b in self.items.values() if b.until <= time]
        for b in gone:
            del self.items[b.id]
        return gone

    def discs(self) -> list[tuple[float, float, float]]:
        return [(*b.centre, b.radius) for b in self.items.values()]

    def cutting(self, a: Point, b: Point) -> Blockage | None:
        return next((k for k in self.items.values() if k.cuts(a, b)), None)

    def signature(self) -> frozenset[str]:
        """What the robot knows about blocked spots now (new evidence changes it)."""
        return frozenset(self.items)


@dataclass(frozen=True)
class NarrowOpening:
    """Free space seen beyond an opening narrower than the robot passes."""

    centre: Point
    width: float  # m, estimated from the grid (cells are 5 cm)
    area_beyond: float  # m^2 of free space seen behind it
    door: str | None = None

    def describe(self, needed: float) -> str:
        name = f"door {self.door}" if self.door else "an opening"
        return (f"{name} about {self.width:.2f} m wide at ({self.centre[0]:.2f}, "
                f"{self.centre[1]:.2f}) leads to {self.area_beyond:.1f} m^2 seen but not "
                f"reachable: the robot needs {needed:.2f} m")


def narrow_openings(grid: OccupancyGrid, robot: Point, radius: float, doors: dict[str, Door],
                    slim: float = 0.12, min_area: float = 0.5) -> list[NarrowOpening]:
    """Free space a slim robot reaches but this one (`radius`: the slimmest disc it would
    squeeze through with) does not come near, with the bottleneck of the widest route there.

    The width is the grid's passing width of the best route (the largest disc that still gets
    from the robot to the region's roomiest cell, plus the grid's half-cell under-estimate on
    each side), found at the narrowest point of that route: not the narrowest point of the
    shortest slim path, which may squeeze between two chairs beside a wide gap."""
    mine = reachable_mask(grid, robot, radius)
    thin = reachable_mask(grid, robot, slim)
    if not thin.any():
        return []
    near = ndimage.binary_dilation(mine, iterations=int(math.ceil(1.5 * radius
                                                                   / grid.resolution)))
    labels, n = ndimage.label(thin & ~near)
    out = []
    clearance = grid.clearance()
    for k in range(1, n + 1):
        cells = np.argwhere(labels == k)
        area = len(cells) * grid.resolution ** 2
        if area < min_area:
            continue
        deep = cells[int(np.argmax(clearance[cells[:, 0], cells[:, 1]]))]
        goal = grid.to_world(deep[None, :])[0]
        goal_xy = (float(goal[0]), float(goal[1]))
        best = _widest_radius(grid, robot, (int(deep[0]), int(deep[1])), slim,
                              min(radius, float(clearance[deep[0], deep[1]])))
        try:
            path = plan_path(grid, robot, goal_xy, best, smooth=False)
        except PathQueryError:
            continue
        if not path.found:
            continue
        points = _densify(np.asarray(path.waypoints), grid.resolution)
        at = grid.to_cell(points)
        values = clearance[at[:, 0], at[:, 1]]
        i = _bottleneck(grid, robot, at, values, best, (int(deep[0]), int(deep[1])))
        centre = (float(points[i, 0]), float(points[i, 1]))
        width = 2.0 * (float(values[i]) + grid.resolution / math.sqrt(2.0))
        door = min(doors.values(), key=lambda d: math.dist(d.centre, centre), default=None)
        name = door.id if door is not None and math.dist(door.centre, centre) < 0.5 else None
        out.append(NarrowOpening(centre, round(width, 2), round(area, 1), name))
    return out


def _widest_radius(grid: OccupancyGrid, robot: Point, cell: tuple[int, int], low: float,
                   high: float, tolerance: float = 0.005) -> float:
    """The largest disc radius in [low, high] (to `tolerance`) whose reachable space from the
    robot holds `cell` (`low` is known to reach it)."""
    if high <= low:
        return low
    if reachable_mask(grid, robot, high)[cell]:
        return high
    while high - low > tolerance:
        mid = 0.5 * (low + high)
        if reachable_mask(grid, robot, mid)[cell]:
            low = mid
        else:
            high = mid
    return low


def _bottleneck(grid: OccupancyGrid, robot: Point, cells: np.ndarray, values: np.ndarray,
                radius: float, goal: tuple[int, int], step: float = 0.02) -> int:
    """The index of the route's narrowest point where a slightly larger disc (`radius` +
    `step`) is cut off: between the last cell near the space such a disc reaches from the
    robot and the first near the goal's part of it (the corners the route hugs elsewhere at
    `radius` are not the bottleneck)."""
    grow = int(math.ceil(step / grid.resolution)) + 1
    robot_side = ndimage.binary_dilation(reachable_mask(grid, robot, radius + step),
                                         iterations=grow)[cells[:, 0], cells[:, 1]]
    labels, _ = ndimage.label(grid.traversable(radius + step))
    theirs = int(labels[goal])
    goal_side = (ndimage.binary_dilation(labels == theirs, iterations=grow)[cells[:, 0],
                                                                           cells[:, 1]]
                 if theirs else np.zeros(len(cells), dtype=bool))
    leave = int(np.nonzero(robot_side)[0].max()) if robot_side.any() else 0
    after = np.nonzero(goal_side[leave:])[0]
    enter = leave + int(after[0]) if len(after) else len(cells) - 1
    return leave + int(np.argmin(values[leave:enter + 1]))


def _densify(points: np.ndarray, step: float) -> np.ndarray:
    """Points every `step` m along a polyline."""
    if len(points) < 2:
        return points
    out = [points[0]]
    for a, b in zip(points, points[1:], strict=False):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        out.extend(a + (b - a) * k / n for k in range(1, n + 1))
    return np.asarray(out)
