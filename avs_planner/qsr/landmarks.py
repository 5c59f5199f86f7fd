"""Landmarks from perception: detections of landmark labels grouped into confirmed landmarks,
each with a facing (its intrinsic front) taken from the 2D map's open side.

A landmark is a label detected at least twice (in two frames) at positions within an agreement
distance; its position is the mean of those detections. Its *facing* is an assumption (see
`conceptual_map/qsr/README.md`): a landmark faces the open side, the mean direction from it to
the cells of the 2D map where the robot can stand within `OPEN_SIDE_RADIUS` (desks stand against
walls or each other and are used from the free side; monitors and keyboards on them face the
same way). Used by the QSR strategies and by the switching planner's QSR-weighted view cones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from conceptual_map.metric import OccupancyGrid
from conceptual_map.qsr import Landmark

OPEN_SIDE_RADIUS = 1.2  # m around a landmark in which standable cells set its facing


@dataclass
class _Cluster:
    label: str
    total: np.ndarray
    n: int = 1
    seen_from: list[tuple[float, float]] = field(default_factory=list)

    @property
    def position(self) -> np.ndarray:
        return self.total / self.n


class LandmarkTracker:
    """Detections of landmark labels grouped per label by distance: a group seen in two
    frames or more is a landmark (a phantom rarely repeats at one spot)."""

    def __init__(self, labels: tuple[str, ...], agree: float, agree_large: float,
                 large: tuple[str, ...] = ("desk", "table")):  # fmt: skip
        self.labels = labels
        self.agree, self.agree_large, self.large = agree, agree_large, large
        self.clusters: list[_Cluster] = []

    def add(self, label: str, position: tuple[float, float, float],
            robot_xy: tuple[float, float]) -> None:  # fmt: skip
        reach = self.agree_large if label in self.large else self.agree
        point = np.asarray(position, dtype=float)
        best, best_d = None, reach
        for c in self.clusters:
            d = float(np.linalg.norm(c.position - point))
            if c.label == label and d <= best_d:
                best, best_d = c, d
        if best is None:
            self.clusters.append(_Cluster(label, point.copy(), 1, [robot_xy]))
        else:
            best.total += point
            best.n += 1
            best.seen_from.append(robot_xy)

    def confirmed(self) -> list[_Cluster]:
        return [c for c in self.clusters if c.n >= 2]


def open_side(grid: OccupancyGrid, xy: np.ndarray, robot_radius: float,
              radius: float = OPEN_SIDE_RADIUS) -> float | None:  # fmt: skip
    """The mean direction from `xy` to the cells within `radius` where the robot can stand
    (None when there are none or they surround it evenly)."""
    res = grid.resolution
    centre = np.asarray(grid.cell_of((float(xy[0]), float(xy[1]))))
    reach = int(math.ceil(radius / res))
    lo = np.maximum(centre - reach, 0)
    hi = np.minimum(centre + reach + 1, np.asarray(grid.shape))
    if np.any(hi <= lo):
        return None
    free = grid.traversable(robot_radius)[lo[0] : hi[0], lo[1] : hi[1]]
    cells = np.argwhere(free) + lo
    if len(cells) == 0:
        return None
    offsets = grid.to_world(cells) - np.asarray(xy[:2])
    dist = np.linalg.norm(offsets, axis=1)
    keep = (dist > 1e-6) & (dist <= radius)
    if not keep.any():
        return None
    mean = (offsets[keep] / dist[keep, None]).mean(axis=0)
    if np.linalg.norm(mean) < 0.05:
        return None
    return float(math.atan2(mean[1], mean[0]))


def landmarks_from(tracker: LandmarkTracker, grid: OccupancyGrid, robot_radius: float
                   ) -> list[Landmark]:  # fmt: skip
    """The confirmed landmarks with their facing: the open side (failing that, towards where
    the robot saw them from). (Snapping it to the long axis of the supporting-plane segment
    under the landmark was tried and made it worse: the segments seen from a few stops are
    fragments of the desk tops.)"""
    out = []
    for i, c in enumerate(tracker.confirmed()):
        xy = c.position[:2]
        facing = open_side(grid, xy, robot_radius)
        if facing is None:
            seen = np.mean(np.asarray(c.seen_from), axis=0) - xy
            facing = float(math.atan2(seen[1], seen[0]))
        out.append(Landmark(c.label, float(xy[0]), float(xy[1]), facing, f"{c.label}#{i + 1}"))
    return out
