"""An n-dimensional log-odds occupancy grid that integrates rays and grows to fit them.

Shared by the 2D occupancy grid and the 3D voxel map. Log-odds are stored as int8 in units of
0.1 (one byte a cell keeps an office-sized voxel map small); each integration updates a cell
once per batch of rays, free cells minus hit cells, as OctoMap does.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from conceptual_map.metric.raycast import traverse
from conceptual_map.metric.sensors import Rays


class CellState(IntEnum):
    """What the robot believes about one cell."""

    UNKNOWN = 0
    FREE = 1
    OCCUPIED = 2


@dataclass(frozen=True)
class SensorModel:
    """Log-odds increments and thresholds, in units of 0.1 log-odds."""

    hit: int = 9
    miss: int = -4
    clamp_min: int = -20
    clamp_max: int = 35
    occupied_at: int = 5  # log-odds >= this: OCCUPIED
    free_at: int = -3  # log-odds <= this: FREE


@dataclass(frozen=True)
class UpdateSummary:
    """Flat indices of the cells one integration updated, and of those whose state changed."""

    touched: np.ndarray
    changed: np.ndarray


class LogOddsGrid:
    """Dense log-odds grid over an axis-aligned box; `origin` is the world corner of cell 0."""

    def __init__(
        self,
        origin: tuple[float, ...],
        shape: tuple[int, ...],
        resolution: float = 0.05,
        model: SensorModel | None = None,
        grow_margin: float = 2.0,
    ):
        if resolution <= 0:
            raise ValueError(f"resolution must be positive, got {resolution}")
        self.resolution = float(resolution)
        self.origin = np.asarray(origin, dtype=float)
        self.logodds = np.zeros(shape, dtype=np.int8)
        self.model = model or SensorModel()
        self.grow_margin = grow_margin

    @property
    def shape(self) -> tuple[int, ...]:
        return self.logodds.shape

    @property
    def ndim(self) -> int:
        return self.logodds.ndim

    def states(self) -> np.ndarray:
        """CellState of every cell, as a uint8 array of the grid's shape."""
        return self._classify(self.logodds)

    def _classify(self, values: np.ndarray) -> np.ndarray:
        out = np.zeros(values.shape, dtype=np.uint8)
        out[values <= self.model.free_at] = CellState.FREE
        out[values >= self.model.occupied_at] = CellState.OCCUPIED
        return out

    def to_cell(self, points: np.ndarray) -> np.ndarray:
        """Integer cell coordinates of world points (N, D) (may lie outside the grid)."""
        return np.floor((np.asarray(points, dtype=float) - self.origin) / self.resolution).astype(
            np.int64
        )

    def to_world(self, cells: np.ndarray) -> np.ndarray:
        """World coordinates of cell centres (N, D)."""
        return self.origin + (np.asarray(cells, dtype=float) + 0.5) * self.resolution

    def inside(self, cells: np.ndarray) -> np.ndarray:
        """Which integer cell coordinates (N, D) lie in the grid."""
        cells = np.asarray(cells)
        if cells.ndim != 2 or cells.shape[1] != self.ndim:
            return np.all((cells >= 0) & (cells < np.asarray(self.shape)), axis=1)
        ok = (cells[:, 0] >= 0) & (cells[:, 0] < self.shape[0])
        for axis in range(1, self.ndim):  # column by column: no (N, D) temporaries
            column = cells[:, axis]
            ok &= (column >= 0) & (column < self.shape[axis])
        return ok

    def integrate(self, rays: Rays, grow: bool = True) -> UpdateSummary:
        """Add one batch of rays: cells passed become freer, end cells of hits more occupied."""
        if grow and rays.starts.shape[0]:
            self.ensure_contains(np.vstack([rays.starts, rays.ends]))
        scale = 1.0 / self.resolution
        _, cells = traverse((rays.starts - self.origin) * scale, (rays.ends - self.origin) * scale)
        passed = self.unique_flat(self._flat(cells))
        hits = self.unique_flat(self._flat(self.to_cell(rays.ends[rays.hit])))
        stamp = self._scratch()
        stamp[hits] = -1
        free = passed[stamp[passed] != -1]
        return self._apply(free, hits)

    def _flat(self, cells: np.ndarray) -> np.ndarray:
        """Flat indices of the cells inside the grid (duplicates kept)."""
        cells = cells[self.inside(cells)]
        if cells.shape[0] == 0:
            return np.zeros(0, dtype=np.int64)
        return np.ravel_multi_index(tuple(cells.T), self.shape)

    def unique_flat(self, flat: np.ndarray) -> np.ndarray:
        """Distinct flat indices in O(n) (no sort): each index keeps the slot that wrote last.

        Rays from one origin repeat many cells; hashing or sorting them was the hot spot.
        """
        stamp = self._scratch()
        order = np.arange(flat.size, dtype=np.int32)
        stamp[flat] = order
        return flat[stamp[flat] == order]

    def _scratch(self) -> np.ndarray:
        """A reusable int32 array with one slot per cell (contents are never relied on)."""
        size = self.logodds.size
        if getattr(self, "_stamp", None) is None or self._stamp.size != size:
            self._stamp = np.empty(size, dtype=np.int32)
        return self._stamp

    def _apply(self, free: np.ndarray, hits: np.ndarray) -> UpdateSummary:
        flat = self.logodds.reshape(-1)
        touched = np.concatenate([free, hits])
        before = self._classify(flat[touched])
        m = self.model
        flat[free] = np.clip(flat[free].astype(np.int16) + m.miss, m.clamp_min, m.clamp_max)
        flat[hits] = np.clip(flat[hits].astype(np.int16) + m.hit, m.clamp_min, m.clamp_max)
        changed = touched[self._classify(flat[touched]) != before]
        return UpdateSummary(touched, changed)

    def reset_cells(self, flat_indices: np.ndarray) -> UpdateSummary:
        """Forget the given cells (back to unknown)."""
        flat = self.logodds.reshape(-1)
        before = self._classify(flat[flat_indices])
        flat[flat_indices] = 0
        return UpdateSummary(flat_indices, flat_indices[before != CellState.UNKNOWN])

    def ensure_contains(self, points: np.ndarray) -> tuple[int, ...]:
        """Grow the grid (with a margin) so every point lies inside; returns the index shift."""
        cells = self.to_cell(points)
        below = np.maximum(0, -cells.min(axis=0))
        above = np.maximum(0, cells.max(axis=0) + 1 - np.asarray(self.shape))
        if not below.any() and not above.any():
            return (0,) * self.ndim
        margin = int(np.ceil(self.grow_margin / self.resolution))
        pad_lo = np.where(below > 0, below + margin, 0)
        pad_hi = np.where(above > 0, above + margin, 0)
        self._pad(tuple(zip(pad_lo.tolist(), pad_hi.tolist(), strict=True)))
        self.origin = self.origin - pad_lo * self.resolution
        return tuple(pad_lo.tolist())

    def _pad(self, widths: tuple[tuple[int, int], ...]) -> None:
        self.logodds = np.pad(self.logodds, widths)
