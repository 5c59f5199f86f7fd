"""The 2D occupancy grid built from laser scans: the basis of MOVE and of travel costs."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy import ndimage

from conceptual_map.metric.logodds import CellState, LogOddsGrid, SensorModel, UpdateSummary
from conceptual_map.metric.sensors import LaserScanLike, laser_rays

_FOUR = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], dtype=bool)


class OccupancyGrid(LogOddsGrid):
    """Free/occupied/unknown cells in the floor plane; grows as scans reach beyond its border."""

    def __init__(
        self,
        origin: tuple[float, float] = (-5.0, -5.0),
        size: tuple[float, float] = (10.0, 10.0),
        resolution: float = 0.05,
        model: SensorModel | None = None,
    ):
        shape = tuple(int(np.ceil(s / resolution)) for s in size)
        super().__init__(origin, shape, resolution, model)
        self.version = 0
        self._cache: dict[tuple, np.ndarray] = {}
        # discs (x, y, r) the robot's centre must keep out of, whatever the cells say: places
        # where its own motion was blocked by something the scans do not show
        self.keep_out: tuple[tuple[float, float, float], ...] = ()

    @classmethod
    def restored(cls, origin: Sequence[float], logodds: np.ndarray, resolution: float,
                 model: SensorModel | None = None) -> OccupancyGrid:
        """A grid holding log-odds kept from an earlier run (`origin`: world corner of cell
        0). New scans update it as any grid: a wall or door that changed since is re-mapped
        by the laser's hits and misses, within the sensor model's clamp."""
        values = np.asarray(logodds)
        if values.ndim != 2 or values.dtype != np.int8:
            raise ValueError(f"a 2D int8 log-odds array is needed, got {values.dtype} "
                             f"with shape {values.shape}")
        grid = cls(origin=(float(origin[0]), float(origin[1])), size=(1.0, 1.0),
                   resolution=resolution, model=model)
        grid.logodds = values.copy()
        grid._touch()
        return grid

    def set_keep_out(self, discs: Sequence[tuple[float, float, float]]) -> None:
        """Replace the keep-out discs (derived grids are recomputed if they changed)."""
        discs = tuple((float(x), float(y), float(r)) for x, y, r in discs)
        if discs != self.keep_out:
            self.keep_out = discs
            self._touch()

    def keep_out_mask(self) -> np.ndarray:
        """Cells whose centre lies in a keep-out disc (cached until the next update)."""

        def build() -> np.ndarray:
            mask = np.zeros(self.shape, dtype=bool)
            for x, y, r in self.keep_out:
                lo = np.maximum(self.to_cell(np.array([[x - r, y - r]]))[0], 0)
                hi = np.minimum(self.to_cell(np.array([[x + r, y + r]]))[0] + 1, self.shape)
                if (hi <= lo).any():
                    continue
                ii, jj = np.mgrid[lo[0]:hi[0], lo[1]:hi[1]]
                centres = self.to_world(np.stack([ii.ravel(), jj.ravel()], axis=1))
                inside = np.hypot(centres[:, 0] - x, centres[:, 1] - y) <= r
                mask[ii.ravel()[inside], jj.ravel()[inside]] = True
            return mask

        return self._cached(("keep_out",), build)

    def integrate_scan(self, scan: LaserScanLike) -> UpdateSummary:
        """Add one laser scan (rays that hit nothing clear space up to max range)."""
        summary = self.integrate(laser_rays(scan))
        self._touch()
        return summary

    def reset_cells(self, flat_indices: np.ndarray) -> UpdateSummary:
        """Forget cells (back to unknown); derived grids are recomputed."""
        summary = super().reset_cells(flat_indices)
        self._touch()
        return summary

    def _touch(self) -> None:
        self.version += 1
        self._cache.clear()

    def _pad(self, widths: tuple[tuple[int, int], ...]) -> None:
        super()._pad(widths)
        self._touch()

    def _cached(self, key: tuple, build) -> np.ndarray:  # noqa: ANN001 - a zero-arg factory
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def state_grid(self) -> np.ndarray:
        """CellState per cell (uint8), cached until the next update."""
        return self._cached(("states",), self.states)

    def frontier_mask(self) -> np.ndarray:
        """Unknown cells with at least one free 4-neighbour (cached until the next update)."""

        def build() -> np.ndarray:
            states = self.state_grid()
            near_free = ndimage.binary_dilation(states == CellState.FREE, structure=_FOUR)
            return near_free & (states == CellState.UNKNOWN)

        return self._cached(("frontier",), build)

    def clearance(self) -> np.ndarray:
        """Distance (m) from each cell centre to the nearest occupied cell, less that cell's
        half-diagonal: a lower bound on the distance to the surface that made it occupied."""

        def build() -> np.ndarray:
            occupied = self.state_grid() == CellState.OCCUPIED
            if not occupied.any():
                return np.full(self.shape, np.inf)
            dist = ndimage.distance_transform_edt(~occupied) * self.resolution
            return dist - self.resolution / np.sqrt(2.0)

        return self._cached(("clearance",), build)

    def traversable(self, robot_radius: float, allow_unknown: bool = False) -> np.ndarray:
        """Cells where a disc of `robot_radius` fits without touching an occupied cell (and
        outside every keep-out disc)."""

        def build() -> np.ndarray:
            states = self.state_grid()
            known_ok = states == CellState.FREE
            if allow_unknown:
                known_ok |= states == CellState.UNKNOWN
            ok = known_ok & (self.clearance() >= robot_radius)
            return ok & ~self.keep_out_mask() if self.keep_out else ok

        return self._cached(("traversable", robot_radius, allow_unknown), build)

    def cell_of(self, xy: tuple[float, float]) -> tuple[int, int]:
        """Cell (i, j) holding a world point (may be outside the grid)."""
        i, j = self.to_cell(np.asarray([xy[:2]]))[0]
        return int(i), int(j)

    def contains(self, cell: tuple[int, int]) -> bool:
        return 0 <= cell[0] < self.shape[0] and 0 <= cell[1] < self.shape[1]

    def segment_clear(
        self, a: tuple[float, float], b: tuple[float, float], mask: np.ndarray
    ) -> bool:
        """True when every cell on the straight segment a-b is True in `mask` (same shape)."""
        step = 0.25 * self.resolution
        n = max(2, int(np.ceil(np.hypot(b[0] - a[0], b[1] - a[1]) / step)) + 1)
        t = np.linspace(0.0, 1.0, n)[:, None]
        points = np.asarray(a[:2])[None, :] * (1 - t) + np.asarray(b[:2])[None, :] * t
        cells = self.to_cell(points)
        if not self.inside(cells).all():
            return False
        return bool(mask[cells[:, 0], cells[:, 1]].all())

    def known_free_area(self) -> float:
        """Square metres of cells believed free."""
        return float((self.state_grid() == CellState.FREE).sum()) * self.resolution**2
