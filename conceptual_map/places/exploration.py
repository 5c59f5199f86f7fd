"""Frontier exploration by nearest placeholder: a driver for tests, benchmarks, explore-only runs.

It only uses what a robot adapter offers (pose, move_along, turn_to, scan, clock) and the
robot's own maps; the planner's MOVE actions go through the executor instead.
"""

from __future__ import annotations

import math
import time as wallclock
from dataclasses import dataclass, field
from enum import Enum
from typing import Protocol

import numpy as np

from conceptual_map.errors import MapError
from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.path_planning import distance_field, plan_path
from conceptual_map.metric.sensors import LaserScanLike
from conceptual_map.places.model import MapEvent
from conceptual_map.places.place_map import PlaceMap


class RobotLike(Protocol):
    """The part of a robot adapter exploration needs."""

    clock: float

    @property
    def pose(self) -> tuple[float, float, float]: ...

    def move_along(self, path: list[tuple[float, float]]) -> object: ...

    def turn_to(self, yaw: float) -> object: ...

    def scan(self) -> LaserScanLike: ...


class ExplorationStatus(Enum):
    COMPLETE = "complete"  # no placeholder left
    STUCK = "stuck"  # placeholders left, none reachable or all tried
    MOVE_LIMIT = "move_limit"


@dataclass
class ExplorationResult:
    status: ExplorationStatus
    moves: int
    distance: float
    sim_time: float
    mapping_wall_time: float  # seconds spent in grid and place-map updates
    mapping_cpu_time: float  # the same, in CPU seconds of this process (robust to a busy machine)
    scans: int
    events: list[MapEvent] = field(default_factory=list)
    failures: list[str] = field(default_factory=list)


@dataclass
class Explorer:
    """Drives to the nearest reachable placeholder, sensing every `step` m, until none is left."""

    robot: RobotLike
    grid: OccupancyGrid
    place_map: PlaceMap
    step: float = 0.5
    max_moves: int = 300
    max_tries: int = 2  # visits to a placeholder that stays unexplored before giving it up
    max_legs: int = 60  # legs of one visit before giving up on it

    def __post_init__(self) -> None:
        self._radius = self.place_map.config.robot_radius
        self._result = ExplorationResult(ExplorationStatus.COMPLETE, 0, 0.0, 0.0, 0.0, 0.0, 0)
        self._tries: dict[str, int] = {}

    def run(self) -> ExplorationResult:
        start = self.robot.clock
        self._look_around()
        while self.place_map.placeholders:
            if self._result.moves >= self.max_moves:
                self._result.status = ExplorationStatus.MOVE_LIMIT
                break
            target = self._nearest_placeholder()
            if target is None:
                self._result.status = ExplorationStatus.STUCK
                break
            self._visit(target)
        self._result.sim_time = self.robot.clock - start
        return self._result

    def _sense(self, poses: list[tuple[float, float, float]]) -> None:
        scan = self.robot.scan()
        began, began_cpu = wallclock.perf_counter(), wallclock.process_time()
        self.grid.integrate_scan(scan)
        events = self.place_map.follow(self.grid, poses, self.robot.clock)
        self._result.mapping_wall_time += wallclock.perf_counter() - began
        self._result.mapping_cpu_time += wallclock.process_time() - began_cpu
        self._result.scans += 1
        self._result.events.extend(events)

    def _look_around(self) -> None:
        self._sense([self.robot.pose])
        self.robot.turn_to(self.robot.pose[2] + math.pi)
        self._sense([self.robot.pose])

    def _nearest_placeholder(self) -> str | None:
        field_ = distance_field(self.grid, self.robot.pose[:2], self._radius)
        best, best_cost = None, math.inf
        for pid, ph in self.place_map.placeholders.items():
            cell = self.grid.cell_of(ph.position)
            if self._tries.get(pid, 0) >= self.max_tries or not self.grid.contains(cell):
                continue
            if field_[cell] < best_cost:
                best, best_cost = pid, float(field_[cell])
        return best

    def _visit(self, target: str) -> None:
        """Drive leg by leg towards a placeholder; replan when a scan blocks the rest of the path
        or the placeholder moved."""
        self._tries[target] = self._tries.get(target, 0) + 1
        legs: list[list[tuple[float, float]]] = []
        goal = None
        for _ in range(self.max_legs):
            placeholder = self.place_map.placeholders.get(target)
            if placeholder is None:
                return  # explored on the way
            if math.dist(self.robot.pose[:2], placeholder.position) < 0.5 * self.grid.resolution:
                break
            if not legs or goal != placeholder.position or not self._still_clear(legs):
                goal = placeholder.position
                legs = self._plan_legs(target, goal)
                if not legs:
                    return
            if not self._drive(target, legs.pop(0)):
                return
        self._look_around()

    def _plan_legs(self, target: str, goal: tuple[float, float]) -> list[list[tuple[float, float]]]:
        try:
            path = plan_path(self.grid, self.robot.pose[:2], goal, self._radius)
        except MapError as exc:
            self._result.failures.append(f"{target}: {exc}")
            return []
        return _legs(path.waypoints, self.step) if path.found else []

    def _still_clear(self, legs: list[list[tuple[float, float]]]) -> bool:
        """The rest of the planned path still keeps the robot radius from what is now known."""
        mask = self.grid.traversable(self._radius)
        points = [self.robot.pose[:2], *(p for leg in legs for p in leg)]
        return all(
            self.grid.segment_clear(a, b, mask) for a, b in zip(points, points[1:], strict=False)
        )

    def _drive(self, target: str, leg: list[tuple[float, float]]) -> bool:
        here = self.robot.pose[:2]
        try:
            self.robot.move_along(leg)
        except Exception as exc:  # noqa: BLE001 - the adapter's own "blocked" error
            self._result.failures.append(f"{target}: {exc}")
            return False
        self._result.moves += 1
        self._result.distance += sum(
            math.dist(a, b) for a, b in zip([here, *leg], leg, strict=False)
        )
        self._sense([(x, y, self.robot.pose[2]) for x, y in leg])
        return True


def _legs(
    waypoints: tuple[tuple[float, float], ...], step: float
) -> list[list[tuple[float, float]]]:
    """Split a polyline (first point = where the robot is) into legs of about `step` metres."""
    legs, current, budget = [], [], step
    for a, b in zip(waypoints, waypoints[1:], strict=False):
        a_, b_ = np.asarray(a), np.asarray(b)
        length = float(np.linalg.norm(b_ - a_))
        travelled = 0.0
        while length - travelled > budget:
            travelled += budget
            point = a_ + (b_ - a_) * travelled / length
            current.append((float(point[0]), float(point[1])))
            legs.append(current)
            current, budget = [], step
        budget -= length - travelled
        current.append((float(b[0]), float(b[1])))
    if current:
        legs.append(current)
    return legs
