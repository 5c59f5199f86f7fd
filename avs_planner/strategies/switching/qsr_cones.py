"""QSR-weighted view cones for the switching planner (Kunze et al. inside Göbelbecker et al.).

When QSR descriptions are known for the target (the task's own, else the default knowledge's),
CREATEVIEWCONES for the target on a support (`(label, on, support)`) no longer spreads
P(ObjectAt) evenly over views around the support: the object-location distribution over the
support is the QSR mixture at the landmarks the robot has perceived, and the cones, and the
probabilities the DT plans with, follow it. In a room (`(label, in, room)`) with a perceived
landmark, the room's uniform cones are kept and half of their probability is shared by the
QSR density they cover.

- **Landmarks come from perception only.** `install` taps the robot adapter's `detect`: every
  detection the episode makes (the DT's looks, watching while driving) also asks for the
  knowledge's landmark labels, at no extra sensing time, and those detections go to a
  `LandmarkTracker` (two agreeing frames make a landmark; facing from the 2D map's open side,
  `avs_planner.qsr.landmarks`). Known objects of a landmark label in the mind (e.g. desks the
  planner confirmed) count too. Nothing here reads the world file or the simulator.
- **The support's area** is the cells of the robot's 2D grid within the executor's
  `support_radius` of the support's detected centre that it has not seen free (a desk's top is
  occupied at its edges and unknown inside; the floor round it is free).
- **Density.** The mixture (`conceptual_map.qsr.build_mixture`) of the target's descriptions at
  the landmarks near the support, evaluated on those cells and normalised, with `FLOOR` of
  uniform mixed in (wrong descriptions leave the rest of the support searchable). No landmark
  near, or no mixture mass on the support: None, and the executor makes its uniform cones.
- **Cones.** Standpoints as `viewcones.support_cones` finds them (12 directions round the
  support, the nearest free one of 0.9 / 1.2 / 1.5 m), each with two headings: at the support's
  centre and at the density-weighted centre of the cells in reach. A greedy covering set picks
  up to `MAX_CONES` views by the density they add (2D wedge of the camera's hfov, 0.9 of the
  detection range, as the room cones use); a cone's probability is P(ObjectAt) times its share
  of the covered density, so the shares sum to P(ObjectAt) as the uniform cones' do, and the
  coverage reported to failed-search evidence is the covered density (at most 0.9, the
  uniform cones' figure).
- **Room cones** keep `viewcones.room_cones`' covering set and coverage; a cone's probability
  becomes the same total shared half by the QSR density it adds over the room's candidate
  cells (occupied and unknown cells next to free space) and half as before (by the cells it
  adds). A first version covered the room greedily by QSR density alone: with only some of
  the room's landmarks perceived it made two cones over the known desks, reported 0.97
  coverage, rejected the room, and a search on `qsr_desks_b` (seed 4) took 41 views instead
  of 6.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from avs_planner.dt import ViewCone
from avs_planner.episode.context import FrameView, Listener
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.viewcones import ConeSet, _room_cells, room_cones
from avs_planner.episode.viewcones import _in_wedge as _in_room_wedge
from avs_planner.qsr.landmarks import LandmarkTracker, open_side
from conceptual_map.metric import CellState
from conceptual_map.qsr import GaussianMixture, Landmark, QsrKnowledge, build_mixture, load_qsr

if TYPE_CHECKING:
    from avs_planner.episode.executor import Executor

FLOOR = 0.05  # share of uniform density mixed into the QSR density over a support
MAX_CONES = 4  # as the uniform support cones
MIN_GAIN = 0.02  # a further cone must add this share of the support's density
LANDMARK_REACH = 2.5  # m from the support's centre: landmarks farther away are left out
DISTANCES = (0.9, 1.2, 1.5)  # m: standpoints round the support (as support_cones)
MAX_COVERAGE = 0.9  # the uniform support cones' coverage
ROOM_SHARE = 0.5  # share of a room's cone probabilities set by the QSR density


@dataclass(frozen=True)
class SupportDensity:
    """The QSR density over one support: cell centres (m, 2), weights summing to 1."""

    points: np.ndarray
    weights: np.ndarray
    landmarks: tuple[Landmark, ...]


class QsrCones:
    """The target's QSR knowledge, the landmarks perceived so far, and cones weighted by them."""

    def __init__(self, executor: Executor, knowledge: QsrKnowledge, target: str, source: str):
        self.ex, self.knowledge, self.target, self.source = executor, knowledge, target, source
        labels = {d.landmark for d in knowledge.descriptions_for(target)}
        labels |= {s.of for d in knowledge.descriptions_for(target) for s in d.chain}
        self.labels = tuple(sorted(lb for lb in labels if lb in knowledge.fronts))
        agree = executor.config.agree
        self.tracker = LandmarkTracker(self.labels, agree[0], agree[1])
        self.weighting = True  # False: landmarks are perceived, cones stay uniform

    # -- perception --

    def observe(self, seen: Sequence[Any], view: FrameView) -> None:
        """Detections of landmark labels (anything with `label` and `position`) in a frame
        taken from `view`."""
        robot_xy = (view.pose[0], view.pose[1])
        for s in seen:
            if s.label in self.labels:
                self.tracker.add(s.label, tuple(s.position), robot_xy)

    def landmarks(self) -> list[Landmark]:
        """Confirmed landmarks, and known objects of landmark labels not already among them,
        each facing the open side of the 2D map."""
        mind = self.ex.mind
        radius = mind.config.robot_radius
        out: list[Landmark] = []
        points = [(c.label, c.position[:2], c.seen_from) for c in self.tracker.confirmed()]
        for obj in mind.objects.values():
            if obj.label not in self.labels:
                continue
            near = self.tracker.agree_large if obj.label in self.tracker.large else \
                self.tracker.agree
            if any(lb == obj.label and math.dist(xy, obj.position[:2]) <= near
                   for lb, xy, _ in points):  # fmt: skip
                continue
            points.append((obj.label, np.asarray(obj.position[:2]), []))
        for i, (label, xy, seen_from) in enumerate(points):
            facing = open_side(mind.grid, np.asarray(xy), radius)
            if facing is None:
                if not seen_from:
                    continue
                back = np.mean(np.asarray(seen_from), axis=0) - xy
                facing = float(math.atan2(back[1], back[0]))
            out.append(Landmark(label, float(xy[0]), float(xy[1]), facing, f"{label}#{i + 1}"))
        return out

    # -- density and cones --

    def density(self, support: KnownObject) -> SupportDensity | None:
        """The QSR density over the support's cells, or None (no landmark near, no mass)."""
        mind = self.ex.mind
        centre = np.asarray(support.position[:2], dtype=float)
        near = tuple(lm for lm in self.landmarks()
                     if math.dist((lm.x, lm.y), centre) <= LANDMARK_REACH)  # fmt: skip
        if not near:
            return None
        points = support_cells(mind.grid, centre, self.ex.config.support_radius)
        if len(points) == 0:
            return None
        result = build_mixture(self.knowledge, self.target, list(near), rng=self.ex.seed)
        if not result.built:
            return None
        weights = qsr_weights(result.mixture, points)
        if weights is None:
            return None
        return SupportDensity(points, weights, near)

    def support_cones(self, label: str, support: KnownObject, p_total: float, key: str
                      ) -> ConeSet | None:  # fmt: skip
        """Cones round `support` weighted by the QSR density (None: use the uniform cones)."""
        if label != self.target or not self.weighting:
            return None
        found = self.density(support)
        if found is None:
            return None
        mind, camera = self.ex.mind, self.ex.camera
        free = mind.grid.traversable(mind.config.robot_radius)
        top = max(0.3, min(2.0 * support.position[2], camera.height - 0.1))
        candidates = standpoint_views(mind.grid, free, support.position[:2], found)
        if not candidates:
            return None
        made = weighted_cones(candidates, found, camera.hfov, 0.9 * camera.detect_range)
        if not made:
            return None
        covered = sum(g for _, g in made)
        cones = tuple(
            ViewCone(f"{key}-{i}", pose, p_total * gain / covered,
                     head=(0.0, -math.atan2(camera.height - top,
                                            math.dist(pose[:2], support.position[:2]))))
            for i, (pose, gain) in enumerate(made))  # fmt: skip
        self.ex.emit("belief", qsr_cones=len(cones), knowledge=self.source,
                     landmarks=[lm.label for lm in found.landmarks],
                     weights=[round(c.probability, 4) for c in cones],
                     covered=round(covered, 3))  # fmt: skip
        return ConeSet(cones, min(covered, MAX_COVERAGE), p_total)

    def room_cones(self, label: str, room: str, p_total: float, key: str) -> ConeSet | None:
        """`viewcones.room_cones` (the same cones, the same coverage) with their probabilities
        shared half by the QSR density they cover and half by the cells they add, as the
        uniform cones are (None: no landmark perceived in the room, or no mass on its cells).

        Only half: the landmarks perceived so far may be some of the room's, and a cone over a
        desk whose keyboard has not been seen must stay worth looking through. The cones and
        their coverage (the failed-search evidence) are the uniform ones, so a rejected room
        is no more certain than before; the DT only looks through the QSR-dense cones first."""
        if label != self.target or not self.weighting:
            return None
        mind, camera = self.ex.mind, self.ex.camera
        made = room_cones(mind, room, label, p_total, camera, key)
        cells = _room_cells(mind, room)
        if not made.cones or len(cells) == 0 or made.coverage <= 0.0:
            return None
        near = [lm for lm in self.landmarks() if mind.room_at((lm.x, lm.y)) == room]
        if not near:
            return None
        result = build_mixture(self.knowledge, self.target, near, rng=self.ex.seed)
        weights = qsr_weights(result.mixture, cells) if result.built else None
        if weights is None:
            return None
        covered = np.zeros(len(cells), dtype=bool)
        qsr_gain = []
        for cone in made.cones:
            mask = _in_room_wedge(cells, cone.pose, camera) & ~covered
            qsr_gain.append(float(weights[mask].sum()))
            covered |= mask
        total_q = sum(qsr_gain)
        total_u = sum(c.probability for c in made.cones)
        if total_q <= 0.0 or total_u <= 0.0:
            return None
        cones = tuple(
            replace(c, probability=total_u * (ROOM_SHARE * q / total_q
                                              + (1.0 - ROOM_SHARE) * c.probability / total_u))
            for c, q in zip(made.cones, qsr_gain, strict=True))  # fmt: skip
        self.ex.emit("belief", qsr_cones=len(cones), knowledge=self.source, room=room,
                     landmarks=[lm.label for lm in near],
                     weights=[round(c.probability, 4) for c in cones],
                     uniform=[round(c.probability, 4) for c in made.cones])
        return ConeSet(cones, made.coverage, made.probability)


def support_cells(grid: Any, centre: np.ndarray, radius: float) -> np.ndarray:
    """Centres (k, 2) of the grid cells within `radius` of `centre` not seen free."""
    res = grid.resolution
    c = np.asarray(grid.cell_of((float(centre[0]), float(centre[1]))))
    reach = int(math.ceil(radius / res))
    lo = np.maximum(c - reach, 0)
    hi = np.minimum(c + reach + 1, np.asarray(grid.shape))
    if np.any(hi <= lo):
        return np.zeros((0, 2))
    states = grid.state_grid()[lo[0] : hi[0], lo[1] : hi[1]]
    cells = np.argwhere(states != CellState.FREE) + lo
    points = grid.to_world(cells)
    return points[np.linalg.norm(points - centre, axis=1) <= radius]


def qsr_weights(mixture: GaussianMixture, points: np.ndarray, floor: float = FLOOR
                ) -> np.ndarray | None:  # fmt: skip
    """The mixture's density at `points`, normalised, with `floor` of uniform mixed in; None
    when the mixture puts (numerically) no mass there."""
    values = mixture.pdf(points)
    total = float(values.sum())
    if not np.isfinite(total) or total <= 1e-12:
        return None
    return (1.0 - floor) * values / total + floor / len(points)


def standpoint_views(grid: Any, free: np.ndarray, centre: Sequence[float],
                     found: SupportDensity) -> list[tuple[float, float, float]]:  # fmt: skip
    """Poses (x, y, yaw): the nearest free standpoint in each of 12 directions round the
    support, looking at its centre and at the density-weighted centre of its cells."""
    sx, sy = float(centre[0]), float(centre[1])
    peak = found.weights @ found.points
    out = []
    for k in range(12):
        angle = k * math.pi / 6
        for distance in DISTANCES:
            x, y = sx + distance * math.cos(angle), sy + distance * math.sin(angle)
            cell = grid.cell_of((x, y))
            if grid.contains(cell) and free[cell]:
                out.append((x, y, math.atan2(sy - y, sx - x)))
                out.append((x, y, math.atan2(peak[1] - y, peak[0] - x)))
                break
    return out


def weighted_cones(candidates: list[tuple[float, float, float]], found: SupportDensity,
                   hfov: float, reach: float, max_cones: int = MAX_CONES,
                   min_gain: float = MIN_GAIN) -> list[tuple[tuple[float, float, float], float]]:
    """Greedy covering by density: up to `max_cones` (pose, density it adds), best first."""
    masks = [_in_wedge(found.points, pose, hfov, reach) for pose in candidates]
    left = found.weights.copy()
    chosen: list[tuple[tuple[float, float, float], float]] = []
    while len(chosen) < max_cones:
        gains = [float(left[m].sum()) for m in masks]
        best = int(np.argmax(gains))
        if gains[best] < min_gain:
            break
        chosen.append((candidates[best], gains[best]))
        left[masks[best]] = 0.0
    return chosen


def _in_wedge(points: np.ndarray, pose: tuple[float, float, float], hfov: float,
              reach: float) -> np.ndarray:  # fmt: skip
    d = points - np.asarray(pose[:2])
    r = np.hypot(d[:, 0], d[:, 1])
    bearing = np.abs((np.arctan2(d[:, 1], d[:, 0]) - pose[2] + np.pi) % (2 * np.pi) - np.pi)
    return (r <= reach) & (bearing <= hfov / 2)


def knowledge_for(task_qsr: QsrKnowledge | None, target: str
                  ) -> tuple[QsrKnowledge, str] | None:  # fmt: skip
    """The task's descriptions when they cover the target, else the default knowledge's; None
    when neither has a description of the target."""
    if task_qsr is not None and task_qsr.descriptions_for(target):
        return task_qsr, "task"
    default = load_qsr()
    return (default, "default") if default.descriptions_for(target) else None


def install(executor: Executor, task_qsr: QsrKnowledge | None, target: str
            ) -> QsrCones | None:  # fmt: skip
    """Give the executor QSR-weighted support cones for `target` when QSRs are known for it,
    and listen to every frame for landmark labels (`SkillContext.detect`)."""
    known = knowledge_for(task_qsr, target)
    if known is None:
        return None
    qsr = QsrCones(executor, known[0], target, known[1])
    if not qsr.labels:
        return None
    executor.context.listeners.append(Listener(qsr.labels, qsr.observe))
    executor.qsr_cones = qsr
    executor.emit("belief", qsr_cones_for=target, knowledge=known[1],
                  landmark_labels=list(qsr.labels))
    return qsr
