"""Frontier-based view sampling (FLAP §3.1): anytime sampling of views aimed at target cells.

A view is a robot pose (base x, y, yaw; torso lift; head pan, tilt) pointing the camera at a
random frontier cell of the search region, with the set of region cells it would see. Most
constraints shape the draw (the FLAP paper's local consistency, so few samples are rejected): the
torso lift fixes the camera height, which with the range band and tilt limits bounds the
horizontal distance, and the azimuth is drawn on the known side of a sideways frontier. The
frontier-normal test (< 90 degrees) and the footprint test on the 2D grid are then checked for
the whole batch at once.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from avs_planner.body import RobotBody
from avs_planner.flap.errors import FlapError
from avs_planner.flap.target import TargetBelief
from avs_planner.flap.visibility import OCCUPIED, Cameras, CastGrid, visible_cells
from conceptual_map.metric import CellState, OccupancyGrid, VoxelMap

_NEIGHBOURS = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)
                        if (i, j, k) != (0, 0, 0)])  # fmt: skip


@dataclass(frozen=True)
class ViewPose:
    """Where the robot stands and how it holds its head (metres, radians; pan is relative)."""

    x: float
    y: float
    yaw: float
    torso: float
    pan: float
    tilt: float

    def camera(self, body: RobotBody) -> tuple[tuple[float, float, float], float, float]:
        """Camera origin, world yaw and pitch of the optical axis."""
        return (self.x, self.y, body.camera_height + self.torso), self.yaw + self.pan, self.tilt


@dataclass(frozen=True, eq=False)
class View:
    """A sensor pose with the unknown region cells it is expected to reveal (a FLAP view)."""

    pose: ViewPose
    target: tuple[float, float, float]
    cells: np.ndarray = field(repr=False)  # sorted region indices (TargetBelief)


@dataclass(frozen=True)
class SamplerOptions:
    """Range band, ray grid and batch size of the sampler (range defaults to detect_range)."""

    min_range: float = 0.5
    max_range: float | None = None
    rays: tuple[int, int] = (24, 18)
    step: float = 0.7  # ray marching step in cells
    batch: int = 64
    min_cells: int = 1
    max_batches: int = 500  # gives up on a region almost nothing can see, even without timeout


class ViewSampler:
    """Samples views for one search region of one map state (build anew after map updates)."""

    def __init__(
        self,
        voxels: VoxelMap,
        grid: OccupancyGrid,
        body: RobotBody,
        belief: TargetBelief,
        options: SamplerOptions | None = None,
    ):
        self.voxels, self.grid, self.body, self.belief = voxels, grid, body, belief
        self.options = options or SamplerOptions()
        self.max_range = self.options.max_range or body.detect_range
        if not 0 <= self.options.min_range < self.max_range:
            raise FlapError(f"sampler range band [{self.options.min_range}, {self.max_range}]")
        self.targets, self.normals = self._frontier_targets()
        self.free_base = grid.traversable(body.footprint_radius)
        self.cast = self._cast_grid()

    def sample(
        self, count: int, timeout: float | None = None, seed: int | np.random.Generator = 0
    ) -> list[View]:
        """Up to `count` views that see at least `min_cells` cells; stops early at `timeout` s."""
        rng = np.random.default_rng(seed)
        views: list[View] = []
        began = time.perf_counter()
        attempts = 0
        while len(views) < count and self.targets.shape[0]:
            if timeout is not None and time.perf_counter() - began > timeout:
                break
            attempts += 1
            if attempts > self.options.max_batches or (attempts > 50 and not views):
                break  # (almost) nothing can be seen from anywhere the robot fits
            views.extend(self._batch(rng)[: count - len(views)])
        return views

    def evaluate(self, views: list[View]) -> list[View]:
        """The same poses with the cells they would see in the current map (views kept from
        the last plan are re-evaluated each cycle); views that see nothing are dropped."""
        if not views:
            return []
        return self._views([v.pose for v in views], [v.target for v in views])

    def _batch(self, rng: np.random.Generator) -> list[View]:
        poses, targets = self.propose(self.options.batch, rng)
        if not poses:
            return []
        return self._views(poses, [tuple(t) for t in targets.tolist()])

    def _views(self, poses: list[ViewPose], targets: list[tuple[float, ...]]) -> list[View]:
        """Ray-cast a batch of poses; keep those that see at least `min_cells` cells."""
        fov = (self.body.hfov, self.body.vfov)
        seen = visible_cells(self.cast, _cameras(poses, self.body), fov, self.max_range,
                             self.options.rays, self.options.step)  # fmt: skip
        return [View(p, t, c) for p, t, c in zip(poses, targets, seen, strict=True)
                if c.size >= self.options.min_cells]  # fmt: skip

    def propose(self, n: int, rng: np.random.Generator) -> tuple[list[ViewPose], np.ndarray]:
        """Up to n poses meeting every constraint, and their target points (world)."""
        b = self.body
        pick = rng.integers(self.targets.shape[0], size=n)
        f, normal = self.targets[pick], self.normals[pick]
        lift = rng.uniform(b.torso.low, b.torso.high, n)  # numpy allows low == high
        dz = f[:, 2] - (b.camera_height + lift)
        r_lo, r_hi = self._distance_band(dz)
        r = rng.uniform(0.0, 1.0, n) * (r_hi - r_lo) + r_lo
        theta = _azimuths(normal, rng)
        x, y = f[:, 0] + r * np.cos(theta), f[:, 1] + r * np.sin(theta)
        tilt = np.arctan2(dz, r)
        to_cam = np.stack([x - f[:, 0], y - f[:, 1], -dz], axis=1)
        ok = (r_hi >= r_lo) & (np.einsum("ij,ij->i", to_cam, normal) > 0.0)
        ok &= (tilt >= b.tilt.low) & (tilt <= b.tilt.high) & self._base_fits(x, y)
        pan = b.pan.clip(0.0)
        yaw = np.arctan2(-to_cam[:, 1], -to_cam[:, 0]) - pan
        poses = [ViewPose(float(x[i]), float(y[i]), _wrap(float(yaw[i])), float(lift[i]), pan,
                          float(tilt[i])) for i in np.nonzero(ok)[0]]  # fmt: skip
        return poses, f[ok]

    def _distance_band(self, dz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Horizontal camera-target distances allowed by the range band and the tilt limits."""
        lo, hi = self.options.min_range, self.max_range
        r_hi = np.sqrt(np.maximum(hi**2 - dz**2, 0.0))
        r_hi = np.where(np.abs(dz) <= hi, r_hi, -1.0)
        r_lo = np.sqrt(np.maximum(lo**2 - dz**2, 0.0))
        tilt = self.body.tilt
        down = -dz / math.tan(-tilt.low) if tilt.low < 0 else np.where(dz < 0, np.inf, 0.0)
        up = dz / math.tan(tilt.high) if tilt.high > 0 else np.where(dz > 0, np.inf, 0.0)
        r_tilt = np.where(dz < 0, down, np.where(dz > 0, up, 0.0))
        return np.maximum(r_lo, r_tilt) + 1e-6, r_hi

    def _base_fits(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        cells = self.grid.to_cell(np.stack([x, y], axis=1))
        inside = self.grid.inside(cells)
        out = np.zeros(x.shape, dtype=bool)
        out[inside] = self.free_base[cells[inside, 0], cells[inside, 1]]
        return out

    def _frontier_targets(self) -> tuple[np.ndarray, np.ndarray]:
        """Frontier (and volume-border unknown) cells of the region, with frontier normals."""
        points, normals = [], []
        for volume in self.belief.volumes:
            found = self.voxels.frontiers_in_box(volume.lo, volume.hi)
            centre = (np.asarray(volume.lo) + np.asarray(volume.hi)) / 2
            points.append(found)
            normals.append(self._normals(found, centre))
        pts, nrm = np.concatenate(points), np.concatenate(normals)
        pts, first = np.unique(pts, axis=0, return_index=True)
        return pts, nrm[first]

    def _normals(self, points: np.ndarray, centre: np.ndarray) -> np.ndarray:
        """Unit frontier normals: mean of free neighbours minus mean of unknown neighbours.

        A cell without free neighbours (unknown on a volume's border) points out of the volume.
        """
        if points.shape[0] == 0:
            return np.zeros((0, 3))
        cells = self.voxels.to_cell(points)
        nb = cells[:, None, :] + _NEIGHBOURS[None, :, :]
        inside = np.all((nb >= 0) & (nb < np.asarray(self.voxels.shape)), axis=2)
        flat = np.ravel_multi_index(tuple(np.clip(nb, 0, np.asarray(self.voxels.shape) - 1)
                                          .transpose(2, 0, 1)), self.voxels.shape)
        states = np.where(inside, self.voxels.states_at(flat), 255)
        free, unknown = states == CellState.FREE, states == CellState.UNKNOWN
        off = _NEIGHBOURS[None, :, :].astype(float)
        mean_free = (off * free[..., None]).sum(1) / np.maximum(free.sum(1), 1)[:, None]
        mean_unknown = (off * unknown[..., None]).sum(1) / np.maximum(unknown.sum(1), 1)[:, None]
        normal = np.where(free.any(1)[:, None], mean_free - mean_unknown, points - centre)
        length = np.linalg.norm(normal, axis=1, keepdims=True)
        return normal / np.where(length > 0, length, 1.0)

    def _cast_grid(self) -> CastGrid:
        """Lookup codes for the ray caster: occupied, pass, or the region index of a cell."""
        codes = self.belief.unknown_lookup(self.voxels)
        occupied = self.voxels.states().reshape(-1) == CellState.OCCUPIED
        codes[occupied] = OCCUPIED
        top = self.voxels.origin + np.asarray(self.voxels.shape) * self.voxels.resolution
        lo = np.maximum(np.array([v.lo for v in self.belief.volumes]), self.voxels.origin)
        hi = np.minimum(np.array([v.hi for v in self.belief.volumes]), top - 1e-6)
        return CastGrid(codes, self.voxels.shape, self.voxels.origin.copy(),
                        self.voxels.resolution, lo, hi)


def _azimuths(normal: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Directions from target to camera: within 90 degrees of a horizontal normal, else any."""
    n = normal.shape[0]
    horizontal = np.hypot(normal[:, 0], normal[:, 1])
    around = np.arctan2(normal[:, 1], normal[:, 0]) + rng.uniform(-np.pi / 2, np.pi / 2, n)
    return np.where(horizontal > 0.3, around, rng.uniform(-np.pi, np.pi, n))


def _cameras(poses: list[ViewPose], body: RobotBody) -> Cameras:
    arr = np.array([(p.x, p.y, p.yaw + p.pan, p.tilt, p.torso) for p in poses])
    origins = np.stack([arr[:, 0], arr[:, 1], body.camera_height + arr[:, 4]], axis=1)
    return Cameras(origins, arr[:, 2], arr[:, 3])


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi
