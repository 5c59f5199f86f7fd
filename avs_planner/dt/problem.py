"""The input of one DT call: view cones, travel costs, detector, sensing cost, rewards.

`DTProblem` validates everything once, so the models, solvers and sessions can trust it.
Costs are in one unit (seconds of robot time, as the time model predicts them); rewards are
negative costs. The terminal penalties make the trade-off explicit: searching longer costs time,
rejecting while the object is there costs `miss_penalty`, confirming a wrong cone costs
`false_confirm_penalty`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from avs_planner.dt.errors import DtInputError
from avs_planner.dt.inputs import DetectorModel, Pose2D, ViewCone

PROBABILITY_TOLERANCE = 1e-9


def _check_cost(value: float, where: str) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise DtInputError(f"{where}: cost {value} must be finite and >= 0")
    return value


@dataclass(frozen=True)
class TravelCosts:
    """Cost to reach each cone's pose from the start pose and from every other cone's pose."""

    from_start: tuple[float, ...]
    between: tuple[tuple[float, ...], ...]

    @classmethod
    def from_lists(cls, from_start: Sequence[float], between: Sequence[Sequence[float]]):
        """Build from plain lists (e.g. JSON); checks shape and values."""
        n = len(from_start)
        start = tuple(_check_cost(c, f"travel from start to cone {i}") for i, c in
                      enumerate(from_start))
        if len(between) != n:
            raise DtInputError(f"travel cost matrix has {len(between)} rows, expected {n}")
        rows = []
        for i, row in enumerate(between):
            if len(row) != n:
                raise DtInputError(f"travel cost matrix row {i} has {len(row)} entries, "
                                   f"expected {n}")
            rows.append(tuple(_check_cost(c, f"travel from cone {i} to cone {j}")
                              for j, c in enumerate(row)))
        return cls(start, tuple(rows))

    @classmethod
    def from_poses(cls, start: Pose2D, cones: Sequence[ViewCone], speed: float = 0.5,
                   turn_speed: float = 1.0) -> TravelCosts:
        """Straight-line driving time plus turning time; callers with a map should pass
        path-based costs instead (walls make straight lines optimistic)."""
        if speed <= 0 or turn_speed <= 0:
            raise DtInputError("travel speeds must be > 0")
        poses = [c.pose for c in cones]
        start_row = [_pose_time(start, p, speed, turn_speed) for p in poses]
        matrix = [[_pose_time(a, b, speed, turn_speed) for b in poses] for a in poses]
        return cls.from_lists(start_row, matrix)


def _pose_time(a: Pose2D, b: Pose2D, speed: float, turn_speed: float) -> float:
    distance = math.hypot(b[0] - a[0], b[1] - a[1])
    turn = abs(math.remainder(b[2] - a[2], math.tau))
    return distance / speed + turn / turn_speed


@dataclass(frozen=True)
class DTRewards:
    """Terminal penalties (positive numbers, paid as negative reward)."""

    miss_penalty: float = 100.0
    false_confirm_penalty: float = 100.0

    def __post_init__(self) -> None:
        _check_cost(self.miss_penalty, "rewards.miss_penalty")
        _check_cost(self.false_confirm_penalty, "rewards.false_confirm_penalty")


@dataclass(frozen=True)
class DTProblem:
    """A validated view-cone search problem; `horizon` bounds the number of actions."""

    cones: tuple[ViewCone, ...]
    travel: TravelCosts
    detector: DetectorModel = field(default_factory=DetectorModel)
    sensing_cost: float = 1.0
    rewards: DTRewards = field(default_factory=DTRewards)
    horizon: int = 0  # 0: default, 2 * (cones with p > 0) + 4

    def __post_init__(self) -> None:
        self._check_cones()
        if len(self.travel.from_start) != self.n:
            raise DtInputError(f"travel costs cover {len(self.travel.from_start)} cones, "
                               f"but {self.n} view cones were given")
        _check_cost(self.sensing_cost, "sensing_cost")
        if self.horizon < 0:
            raise DtInputError(f"horizon {self.horizon} must be >= 0")
        if self.horizon == 0:
            object.__setattr__(self, "horizon", 2 * len(self.relevant_cones) + 4)

    def _check_cones(self) -> None:
        seen: set[str] = set()
        for i, cone in enumerate(self.cones):
            cone.check(f"view cone {i}")
            if cone.id in seen:
                raise DtInputError(f"view cone {i}: duplicate id {cone.id!r}")
            seen.add(cone.id)
        total = sum(c.probability for c in self.cones)
        if total > 1.0 + PROBABILITY_TOLERANCE:
            raise DtInputError(f"view cone probabilities sum to {total:.6g} > 1 "
                               "(they are P(target in cone i), mutually exclusive)")

    @property
    def n(self) -> int:
        return len(self.cones)

    @cached_property
    def prior(self) -> tuple[float, ...]:
        """P(target in cone i), then P(target in none) as the last entry."""
        probs = [c.probability for c in self.cones]
        return (*probs, max(0.0, 1.0 - sum(probs)))

    @cached_property
    def relevant_cones(self) -> tuple[int, ...]:
        """Cones that can hold the target (prior > 0); others are never worth visiting."""
        return tuple(i for i, c in enumerate(self.cones) if c.probability > 0.0)

    @cached_property
    def metric(self) -> bool:
        """True if no detour through another cone is cheaper than the direct move."""
        rows = np.array(self._travel_rows)  # (n + 1) x n, start row last
        if self.n == 0:
            return True
        between = rows[: self.n]
        via = (rows[:, :, None] + between[None, :, :]).min(axis=1)  # best one-stop detour
        return bool((via >= rows - 1e-9).all())

    @cached_property
    def _travel_rows(self) -> tuple[tuple[float, ...], ...]:
        # rows[robot][cone]; robot START (-1) indexes the last row, the start pose's row
        rows = [tuple(0.0 if i == j else c for j, c in enumerate(row))
                for i, row in enumerate(self.travel.between)]
        return (*rows, self.travel.from_start)

    def travel_cost(self, robot: int, cone: int) -> float:
        """Cost to move from robot position (START or a cone index) to `cone`."""
        return self._travel_rows[robot][cone]

    @cached_property
    def detection_rates(self) -> tuple[float, float]:
        """(P(detection | target in cone), P(detection | not in cone))."""
        return self.detector.p_detect(True), self.detector.p_detect(False)

    @cached_property
    def look_weights(self) -> tuple[tuple[tuple[int, float], ...], ...]:
        """Per robot position (START last): (cone, 1 / (travel + sensing)) of relevant cones,
        for the greedy p/cost ratio."""
        return tuple(
            tuple((c, 1.0 / max(row[c] + self.sensing_cost, 1e-12)) for c in self.relevant_cones)
            for row in self._travel_rows
        )
