"""View selection for indirect search (Kunze et al., eq. 2 and Algorithm 1).

Sample n navigable poses, score each 2D view cone by the density of the supporting-plane voxels
inside it, take the best pose; there, rank nine 3D frustums (3 pans x 3 tilts within the head's
limits) by the density they contain. The three methods of the QSR paper's experiments differ only
in the density and the choice: `qsr` (P_QSR), `supporting-planes` (uniform over plane voxels,
best cone) and `random` (a random one of the n poses; its head is still pointed by the uniform
density).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from typing import Any

import numpy as np

from avs_planner.body import RobotBody
from avs_planner.errors import AvsError
from avs_planner.qsr.geometry import in_frustums, in_view_cones, line_of_sight
from avs_planner.qsr.poses import sample_poses
from conceptual_map.metric import OccupancyGrid
from conceptual_map.metric.path_planning import distance_field


class ViewSelectionError(AvsError):
    """Inputs view selection cannot use (density of the wrong length, QSR without a density)."""


class ViewMethod(Enum):
    QSR = "qsr"
    SUPPORTING_PLANES = "supporting-planes"
    RANDOM = "random"


class SelectionStatus(Enum):
    SELECTED = "selected"
    NO_SUPPORT = "no_support"  # no supporting-plane voxels to look at
    NO_POSES = "no_poses"  # no navigable cell within range of the planes


@dataclass(frozen=True)
class ScoredPose:
    """A view pose and its eq. 2 score (density in its 2D view cone)."""

    x: float
    y: float
    yaw: float
    score: float


@dataclass(frozen=True)
class Frustum:
    """A head setting at the chosen pose (radians, pan relative to the base) and its score."""

    pan: float
    tilt: float
    score: float


@dataclass(frozen=True)
class ViewOptions:
    """Knobs of the selection; None means the body's value (hfov / 2, detect range), and no
    `start` means any traversable cell counts as navigable."""

    n_poses: int = 20
    cone_half_angle: float | None = None
    pan_sweep: float = 0.0  # rad the head may pan each way to widen the 2D cone (body-limited)
    max_range: float | None = None
    torso: float = 0.0  # m of torso lift used for the frustums' camera height
    start: tuple[float, float] | None = None  # the robot's position: only poses reachable from it
    occlusion: Any = None  # a VoxelMap: voxels hidden behind occupied ones are not in view


@dataclass(frozen=True)
class ViewSelection:
    """The chosen pose, all sampled poses with their scores, and the ranked frustums."""

    status: SelectionStatus
    method: ViewMethod
    best: ScoredPose | None
    poses: tuple[ScoredPose, ...]
    frustums: tuple[Frustum, ...]

    @property
    def selected(self) -> bool:
        return self.status is SelectionStatus.SELECTED


def select_view(
    grid: OccupancyGrid,
    points: np.ndarray,
    density: np.ndarray | None,
    body: RobotBody,
    method: ViewMethod | str = ViewMethod.QSR,
    rng: np.random.Generator | int | None = 0,
    options: ViewOptions | None = None,
) -> ViewSelection:
    """Algorithm 1: the best of n sampled poses for `method`, and its ranked frustums.

    `points` are the supporting-plane voxel centres (m, 3); `density` is P_QSR over them
    (required for `qsr`); the other methods use a uniform density, or `density` when one is
    given (a search's belief: uniform, less where it has already looked).
    """
    method = ViewMethod(method)
    options = options or ViewOptions()
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    weights = _density(method, points, density)
    if points.shape[0] == 0:
        return ViewSelection(SelectionStatus.NO_SUPPORT, method, None, (), ())
    return _select(grid, points, weights, body, method, np.random.default_rng(rng), options)


def _density(method: ViewMethod, points: np.ndarray, density: np.ndarray | None) -> np.ndarray:
    if method is not ViewMethod.QSR and density is None:
        return np.full(points.shape[0], 1.0 / max(1, points.shape[0]))
    if density is None:
        raise ViewSelectionError("the qsr method needs a density over the plane voxels")
    density = np.asarray(density, dtype=float).reshape(-1)
    if density.shape[0] != points.shape[0]:
        raise ViewSelectionError(f"density has {density.shape[0]} values for "
                                 f"{points.shape[0]} plane voxels")  # fmt: skip
    return density


def _select(
    grid: OccupancyGrid,
    points: np.ndarray,
    weights: np.ndarray,
    body: RobotBody,
    method: ViewMethod,
    rng: np.random.Generator,
    options: ViewOptions,
) -> ViewSelection:
    half = options.cone_half_angle or cone_half_angle(body, options.pan_sweep)
    reach = options.max_range or body.detect_range
    poses = sample_poses(grid, points, options.n_poses, body.footprint_radius, reach, rng,
                         options.start)  # fmt: skip
    if poses.shape[0] == 0:
        return ViewSelection(SelectionStatus.NO_POSES, method, None, (), ())
    scores, visible = _scores(poses, points, weights, body, options, half, reach)
    k = int(rng.integers(len(poses))) if method is ViewMethod.RANDOM else int(np.argmax(scores))
    scored = tuple(ScoredPose(*map(float, p), float(s)) for p, s in zip(poses, scores, strict=True))
    frustums = rank_frustums(poses[k], points, weights, body, reach, options.torso,
                             None if visible is None else visible[k])
    return ViewSelection(SelectionStatus.SELECTED, method, scored[k], scored, frustums)


def _scores(
    poses: np.ndarray, points: np.ndarray, weights: np.ndarray, body: RobotBody,
    options: ViewOptions, half: float, reach: float,
) -> tuple[np.ndarray, np.ndarray | None]:  # fmt: skip
    """Eq. 2 per pose, with line of sight through `options.occlusion` when it is given (then
    also the (n, m) visibility mask)."""
    if options.occlusion is None:
        return score_cones(poses, points, weights, half, reach), None
    camera_z = body.camera_height + body.torso.clip(options.torso)
    cameras = np.column_stack([poses[:, :2], np.full(len(poses), camera_z)])
    cones = in_view_cones(poses, points, half, reach)
    visible = line_of_sight(options.occlusion, cameras, points, cones)
    return (cones & visible).astype(float) @ weights, visible


def score_poses(
    poses: np.ndarray, points: np.ndarray, density: np.ndarray, body: RobotBody,
    options: ViewOptions | None = None,
) -> np.ndarray:  # fmt: skip
    """Eq. 2's score of given poses (n, 3), e.g. where the robot stands, as `select_view`
    scores its samples (same cone, range and occlusion options)."""
    options = options or ViewOptions()
    poses = np.asarray(poses, dtype=float).reshape(-1, 3)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    density = np.asarray(density, dtype=float).reshape(-1)
    if density.shape[0] != points.shape[0]:
        raise ViewSelectionError(f"density has {density.shape[0]} values for "
                                 f"{points.shape[0]} plane voxels")  # fmt: skip
    if poses.shape[0] == 0 or points.shape[0] == 0:
        return np.zeros(poses.shape[0])
    half = options.cone_half_angle or cone_half_angle(body, options.pan_sweep)
    reach = options.max_range or body.detect_range
    return _scores(poses, points, density, body, options, half, reach)[0]


def pose_times(
    poses: tuple[ScoredPose, ...], grid: OccupancyGrid, start: tuple[float, float, float],
    body: RobotBody,
) -> np.ndarray:
    """Seconds from the robot's pose `start` to each pose: grid-path distance at the body's
    speed, turning onto the straight line and then to the pose's heading (a differential
    base; an omni base only turns to the heading); inf where the grid has no path."""
    x, y, yaw = start
    field = distance_field(grid, (x, y), body.footprint_radius)
    out = np.full(len(poses), np.inf)
    for k, p in enumerate(poses):
        cell = grid.cell_of((p.x, p.y))
        if not grid.contains(cell) or not math.isfinite(dist := float(field[cell])):
            continue
        line = math.atan2(p.y - y, p.x - x)
        turn = (body.turn_time(line - yaw) + body.turn_time(p.yaw - line)
                if dist > 1e-6 and not body.holonomic else body.turn_time(p.yaw - yaw))
        out[k] = body.drive_time(dist) + turn
    return out


def best_rate(
    poses: tuple[ScoredPose, ...], grid: OccupancyGrid, start: tuple[float, float, float],
    body: RobotBody, look_s: float,
) -> ScoredPose | None:
    """The pose with the most eq. 2 score per second of getting there and looking for
    `look_s`: the utility p/t of Sarmiento et al. that FLAP (Gedicke et al., eq. 6) plans
    with, where p is the belief's mass in the pose's cone. None if no pose is reachable."""
    rates = pose_rates(poses, grid, start, body, look_s)
    if not len(poses) or not np.isfinite(rates).any():
        return None
    return poses[int(np.argmax(rates))]


def pose_rates(
    poses: tuple[ScoredPose, ...], grid: OccupancyGrid, start: tuple[float, float, float],
    body: RobotBody, look_s: float,
) -> np.ndarray:  # fmt: skip
    """`best_rate`'s utility of every pose: eq. 2 score / (seconds to get there + `look_s`);
    -inf where the grid has no path."""
    if look_s <= 0.0:
        raise ViewSelectionError(f"look_s must be > 0 s, got {look_s}")
    if not len(poses):
        return np.zeros(0)
    times = pose_times(poses, grid, start, body) + look_s
    rates = np.array([p.score for p in poses]) / times
    return np.where(np.isfinite(times), rates, -np.inf)


def cone_half_angle(body: RobotBody, pan_sweep: float = 0.0) -> float:
    """Half-angle of the 2D view cone: half the camera's hfov, widened by a pan sweep that the
    head can make both ways (the QSR paper's 60 degree cone "as the pan-tilt unit can cover
    more")."""
    sweep = max(0.0, min(pan_sweep, body.pan.high, -body.pan.low))
    return min(math.pi, body.hfov / 2.0 + sweep)


def score_cones(
    poses: np.ndarray, points: np.ndarray, density: np.ndarray, half_angle: float,
    max_range: float,
) -> np.ndarray:  # fmt: skip
    """Eq. 2's sums: sum_i P(v_i) In(v_i, Viewcone(psi)) for every pose psi (n,)."""
    return in_view_cones(poses, points, half_angle, max_range).astype(float) @ density


def frustum_settings(
    pose: np.ndarray, points: np.ndarray, density: np.ndarray, body: RobotBody, camera_z: float,
    max_range: float,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Nine (pan, tilt) pairs: pans 0 and +-hfov/2, tilts aimed at the density-weighted centre of
    the voxels ahead and +-vfov/2 from there, all clipped to the head's limits (duplicates
    dropped, centre first so that ties keep the straight view)."""
    centre = _aim_point(pose, points, density, body.hfov, max_range)
    aim = math.atan2(centre[2] - camera_z, math.hypot(*(centre[:2] - pose[:2])))
    pans = [body.pan.clip(p) for p in (0.0, -body.hfov / 2.0, body.hfov / 2.0)]
    tilts = [body.tilt.clip(aim + t) for t in (0.0, -body.vfov / 2.0, body.vfov / 2.0)]
    pairs = list(dict.fromkeys((p, t) for p in pans for t in tilts))
    return np.array([p for p, _ in pairs]), np.array([t for _, t in pairs])


def _aim_point(
    pose: np.ndarray, points: np.ndarray, density: np.ndarray, width: float, max_range: float
) -> np.ndarray:
    """Density-weighted centre of the voxels within `width` of the heading (their plain centre
    when they carry no density, all voxels' when none is ahead)."""
    ahead = in_view_cones(pose[None, :], points, width, max_range)[0]
    if not ahead.any():
        return points.mean(axis=0)
    w = density[ahead]
    return (w @ points[ahead]) / w.sum() if w.sum() > 0 else points[ahead].mean(axis=0)


def rank_frustums(
    pose: np.ndarray, points: np.ndarray, density: np.ndarray, body: RobotBody,
    max_range: float, torso: float = 0.0, visible: np.ndarray | None = None,
) -> tuple[Frustum, ...]:  # fmt: skip
    """The frustums at `pose`, best first, scored like eq. 2 with In_3D (and only the voxels
    set in `visible`, when given: those not hidden from the pose)."""
    camera_z = body.camera_height + body.torso.clip(torso)
    pans, tilts = frustum_settings(pose, points, density, body, camera_z, max_range)
    camera = np.array([pose[0], pose[1], camera_z])
    mask = in_frustums(camera, pose[2] + pans, tilts, points, (body.hfov, body.vfov), max_range)
    if visible is not None:
        mask &= visible[None, :]
    scores = mask.astype(float) @ density
    order = np.argsort(-scores, kind="stable")
    return tuple(Frustum(float(pans[i]), float(tilts[i]), float(scores[i])) for i in order)
