"""Transition times between views (FLAP §3.2): the robot's time model over grid paths.

`exact_time` plans an A* path and prices it with the RobotBody (turns, driving, torso, head,
sensing). `build_table` is the FLAP paper's lookup table: view positions are clustered, one
Dijkstra sweep per cluster gives grid distances, and driving time is a linear regression of
exact path times over those distances, fitted on a few sampled pairs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.cluster.vq import kmeans2

from avs_planner.body import RobotBody
from avs_planner.flap.errors import FlapError
from avs_planner.flap.sampling import ViewPose
from conceptual_map.metric import OccupancyGrid, distances_at, plan_path


@dataclass(frozen=True)
class TransitionTable:
    """Predicted seconds from the robot's pose (`start`) and between views (`times`).

    `kept` lists the input views reachable from the start; rows and columns follow it.
    """

    start: np.ndarray  # (n,)
    times: np.ndarray  # (n, n)
    kept: np.ndarray  # (n,) indices into the views given to build_table
    labels: np.ndarray  # (n,) cluster of each kept view
    drive_fit: tuple[float, float]  # seconds = a + b * grid distance (m)
    samples: tuple[tuple[float, float], ...] = ()  # (grid m, driving s) pairs of this fit


def fixed_time(body: RobotBody, a: ViewPose, b: ViewPose) -> float:
    """Seconds at b apart from driving and turning: torso, head, one sensing step."""
    return (body.torso_time(b.torso - a.torso) + body.head_time(b.pan - a.pan, b.tilt - a.tilt)
            + sensing_time(body))  # fmt: skip


def turn_estimate(body: RobotBody, a: ViewPose, b: ViewPose) -> float:
    """Base turning a -> b as the table predicts it: a differential base turns onto the line
    a-b and then to b's yaw; an omni base (or one that does not move) only to b's yaw."""
    if body.holonomic or math.hypot(b.x - a.x, b.y - a.y) < 1e-6:
        return body.turn_time(b.yaw - a.yaw)
    line = math.atan2(b.y - a.y, b.x - a.x)
    return body.turn_time(line - a.yaw) + body.turn_time(b.yaw - line)


def sensing_time(body: RobotBody) -> float:
    """A depth frame and a detection at the view pose."""
    return body.scan_time + body.sensing_time


def exact_time(body: RobotBody, grid: OccupancyGrid, a: ViewPose, b: ViewPose) -> float:
    """Seconds from pose a to view b along an A* path (inf if there is none)."""
    if math.hypot(b.x - a.x, b.y - a.y) < 1e-9:
        return body.turn_time(b.yaw - a.yaw) + fixed_time(body, a, b)
    path = plan_path(grid, (a.x, a.y), (b.x, b.y), body.footprint_radius)
    if not path.found:
        return math.inf
    drive, heading = path_time(body, (a.x, a.y, a.yaw), path.waypoints)
    return drive + body.turn_time(b.yaw - heading) + fixed_time(body, a, b)


def path_time(
    body: RobotBody, start: tuple[float, float, float], points: Sequence[tuple[float, float]]
) -> tuple[float, float]:
    """Seconds to follow waypoints (a differential base turns onto each segment), and the
    heading on arrival."""
    x, y, yaw = start
    total = 0.0
    for px, py in points:
        dist = math.hypot(px - x, py - y)
        if dist > 1e-9 and not body.holonomic:
            heading = math.atan2(py - y, px - x)
            total += body.turn_time(heading - yaw)
            yaw = heading
        total += body.drive_time(dist)
        x, y = px, py
    return total, yaw


def build_table(
    body: RobotBody,
    grid: OccupancyGrid,
    start: ViewPose,
    poses: Sequence[ViewPose],
    clusters: int = 50,
    fit_pairs: int = 16,
    seed: int = 0,
    known: Sequence[tuple[float, float]] = (),
) -> TransitionTable:
    """The lookup table over clustered view poses; views unreachable from the start are left out.

    The driving regression is fitted on `fit_pairs` exact A* times plus the (grid distance,
    driving seconds) pairs in `known` (e.g. an earlier cycle's `samples`: a continual search
    then prices only a few new paths per cycle)."""
    if not poses:
        raise FlapError("a transition table needs at least one view")
    rng = np.random.default_rng(seed)
    xy = np.array([(p.x, p.y) for p in poses])
    labels, reps = _cluster(xy, clusters, rng)
    at_views = distances_at(grid, [(start.x, start.y)] + [tuple(xy[r]) for r in reps],
                            grid.to_cell(xy), body.footprint_radius)  # (1 + k, n) grid metres
    kept = np.nonzero(np.isfinite(at_views[0]))[0]
    if kept.size == 0:
        raise FlapError("no view is reachable from the robot's pose")
    poses = [poses[i] for i in kept]
    from_start = at_views[0, kept]
    lengths = _view_lengths(labels[kept], at_views[1:][:, kept], from_start)
    new = _drive_samples(body, grid, start, poses, from_start, lengths, fit_pairs, rng)
    samples = (*known, *new)
    fit = _fit_drive(body, samples)
    return TransitionTable(
        start=_compose(body, [start], poses, from_start[None, :], fit)[0],
        times=_compose(body, poses, poses, lengths, fit),
        kept=kept, labels=labels[kept], drive_fit=fit, samples=samples,
    )  # fmt: skip


def _cluster(xy: np.ndarray, k: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """k-means labels of the view positions and, per cluster, the member nearest its mean."""
    if xy.shape[0] <= k:
        return np.arange(xy.shape[0]), np.arange(xy.shape[0])
    centres, labels = kmeans2(xy, k, minit="++", seed=rng)
    used, labels = np.unique(labels, return_inverse=True)
    gap = np.linalg.norm(xy - centres[used][labels], axis=1)
    reps = np.array([np.flatnonzero(labels == c)[np.argmin(gap[labels == c])]
                     for c in range(used.size)])  # fmt: skip
    return labels, reps


def _view_lengths(labels: np.ndarray, fields: np.ndarray, from_start: np.ndarray) -> np.ndarray:
    """Grid distances between views: through the representative of either view's cluster
    (rep->i plus rep->j), or through the start when that is shorter."""
    n = labels.size
    own = fields[labels, np.arange(n)]  # each view to its representative
    via = own[:, None] + fields[labels, :]  # i -> rep(i) -> j
    lengths = np.minimum(via, via.T)
    lengths = np.minimum(lengths, from_start[:, None] + from_start[None, :])
    np.fill_diagonal(lengths, 0.0)
    return lengths


def _drive_samples(
    body: RobotBody,
    grid: OccupancyGrid,
    start: ViewPose,
    poses: list[ViewPose],
    from_start: np.ndarray,
    lengths: np.ndarray,
    pairs: int,
    rng: np.random.Generator,
) -> list[tuple[float, float]]:
    """(grid distance, driving seconds of the exact A* time) for up to `pairs` random pairs."""
    everyone = [start] + poses
    grid_len = np.vstack([from_start[None, :], lengths])  # row 0: the start
    out = []
    for _ in range(pairs):
        i, j = int(rng.integers(len(everyone))), int(rng.integers(len(poses)))
        if grid_len[i, j] < 1e-6:
            continue
        a, b = everyone[i], poses[j]
        exact = exact_time(body, grid, a, b)
        if math.isfinite(exact):
            out.append((float(grid_len[i, j]),
                        exact - fixed_time(body, a, b) - turn_estimate(body, a, b)))
    return out


def _fit_drive(body: RobotBody, samples: Sequence[tuple[float, float]]) -> tuple[float, float]:
    """Least-squares a, b of driving seconds = a + b * grid distance."""
    xs = np.array([x for x, _ in samples])
    ys = np.array([y for _, y in samples])
    if xs.size < 3 or np.ptp(xs) < 1e-3:
        return 0.0, 1.0 / body.linear_speed
    coef, *_ = np.linalg.lstsq(np.stack([np.ones(xs.size), xs], axis=1), ys, rcond=None)
    return float(coef[0]), float(coef[1])


def _compose(
    body: RobotBody,
    origins: Sequence[ViewPose],
    targets: Sequence[ViewPose],
    lengths: np.ndarray,
    fit: tuple[float, float],
) -> np.ndarray:
    """Seconds (len(origins), len(targets)): fitted driving plus turns, torso, head, sensing."""
    o = np.array([(p.x, p.y, p.yaw, p.torso, p.pan, p.tilt) for p in origins])
    t = np.array([(p.x, p.y, p.yaw, p.torso, p.pan, p.tilt) for p in targets])
    d = t[None, :, :] - o[:, None, :]
    torso = np.abs(d[..., 3]) / body.torso_speed
    head = np.maximum(np.abs(d[..., 4]) / body.pan_speed, np.abs(d[..., 5]) / body.tilt_speed)
    drive = np.where(lengths > 1e-6, np.maximum(fit[0] + fit[1] * lengths, 0.0), 0.0)
    return drive + _turns(body, o, t, d) + torso + head + sensing_time(body)


def _turns(body: RobotBody, o: np.ndarray, t: np.ndarray, d: np.ndarray) -> np.ndarray:
    """`turn_estimate` for every origin-target pair at once."""
    direct = _abs_wrap(d[..., 2]) / body.angular_speed
    if body.holonomic:
        return direct
    line = np.arctan2(d[..., 1], d[..., 0])
    via = (_abs_wrap(line - o[:, None, 2]) + _abs_wrap(t[None, :, 2] - line)) / body.angular_speed
    return np.where(np.hypot(d[..., 0], d[..., 1]) < 1e-6, direct, via)


def _abs_wrap(angle: np.ndarray) -> np.ndarray:
    return np.abs((angle + np.pi) % (2 * np.pi) - np.pi)
