"""The 3D voxel map (FLAP §3.1): free/occupied/unknown cells with an incremental frontier set.

Frontier cells are unknown cells with at least one free 6-neighbour. After every update only
the cells whose state changed, and their neighbours, are re-examined.
"""

from __future__ import annotations

import numpy as np

from conceptual_map.metric.logodds import CellState, LogOddsGrid, SensorModel, UpdateSummary
from conceptual_map.metric.sensors import DepthFrameLike, Rays, depth_rays


class VoxelMap(LogOddsGrid):
    """Dense 3D grid over a fixed box (an office of 12 x 8 x 2 m at 5 cm is 1.5 MB)."""

    def __init__(
        self,
        origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
        size: tuple[float, float, float] = (12.0, 8.0, 2.0),
        resolution: float = 0.05,
        model: SensorModel | None = None,
        grow: bool = False,
    ):
        shape = tuple(int(np.ceil(s / resolution)) for s in size)
        super().__init__(origin, shape, resolution, model)
        self.grow = grow
        self.frontier = np.zeros(shape, dtype=bool)

    def integrate_depth(self, frame: DepthFrameLike) -> UpdateSummary:
        """Add one depth frame; rays leaving the box are cut at its border unless `grow`."""
        return self.integrate_rays(depth_rays(frame))

    def integrate_rays(self, rays: Rays) -> UpdateSummary:
        summary = self.integrate(rays, grow=self.grow)
        self._refresh_frontier(summary.changed)
        return summary

    def _pad(self, widths: tuple[tuple[int, int], ...]) -> None:
        super()._pad(widths)
        self.frontier = np.pad(self.frontier, widths)

    def frontier_cells(self) -> np.ndarray:
        """Integer coordinates (N, 3) of all frontier cells."""
        return np.argwhere(self.frontier)

    def frontier_points(self) -> np.ndarray:
        """World coordinates (N, 3) of the centres of all frontier cells."""
        return self.to_world(self.frontier_cells())

    def compute_frontier(self) -> np.ndarray:
        """The frontier mask recomputed from scratch (what the incremental set must equal)."""
        states = self.states()
        near_free = np.zeros(self.shape, dtype=bool)
        free = states == CellState.FREE
        for axis in range(3):
            for shift in (1, -1):
                near_free |= _shift(free, axis, shift)
        return near_free & (states == CellState.UNKNOWN)

    def reset_box(self, lo: tuple[float, ...], hi: tuple[float, ...]) -> UpdateSummary:
        """Forget everything inside the world box [lo, hi] (FLAP: the region may have changed)."""
        flat = np.ravel_multi_index(tuple(self._box_cells(lo, hi).T), self.shape)
        summary = self.reset_cells(flat)
        self._refresh_frontier(summary.changed)
        return summary

    def unknown_in_box(self, lo: tuple[float, ...], hi: tuple[float, ...]) -> np.ndarray:
        """World centres (N, 3) of unknown cells whose centres lie in the box [lo, hi]."""
        return self.to_world(self._cells_in_state(lo, hi, CellState.UNKNOWN))

    def frontiers_in_box(
        self, lo: tuple[float, ...], hi: tuple[float, ...], include_border_unknown: bool = True
    ) -> np.ndarray:
        """World centres of frontier cells in the box; FLAP adds unknown cells on its border
        so that a region enclosed in unknown space still yields view targets."""
        cells = self._box_cells(lo, hi)
        if cells.shape[0] == 0:
            return np.zeros((0, 3))
        index = tuple(cells.T)
        keep = self.frontier[index]
        if include_border_unknown:
            first, last = cells.min(axis=0), cells.max(axis=0)
            border = np.any((cells == first) | (cells == last), axis=1)
            keep |= border & (self.states()[index] == CellState.UNKNOWN)
        return self.to_world(cells[keep])

    def cells_in_box(self, lo: tuple[float, ...], hi: tuple[float, ...]) -> np.ndarray:
        """Integer coordinates (N, 3) of the cells whose centres lie in the box [lo, hi]."""
        return self._box_cells(lo, hi)

    def states_at(self, flat: np.ndarray) -> np.ndarray:
        """CellState (uint8) of the cells with the given flat indices."""
        return self._classify(self.logodds.reshape(-1)[np.asarray(flat, dtype=np.int64)])

    def _cells_in_state(self, lo: tuple[float, ...], hi: tuple[float, ...], state: int):
        cells = self._box_cells(lo, hi)
        if cells.shape[0] == 0:
            return cells
        values = self._classify(self.logodds[tuple(cells.T)])
        return cells[values == state]

    def _box_cells(self, lo: tuple[float, ...], hi: tuple[float, ...]) -> np.ndarray:
        """Cells whose centres lie in [lo, hi], clipped to the grid."""
        lo_a, hi_a = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        if lo_a.shape != (3,) or hi_a.shape != (3,) or np.any(hi_a < lo_a):
            raise ValueError(f"box needs lo <= hi, three numbers each; got {lo!r}, {hi!r}")
        first = np.ceil((lo_a - self.origin) / self.resolution - 0.5).astype(int)
        last = np.floor((hi_a - self.origin) / self.resolution - 0.5).astype(int)
        first = np.maximum(first, 0)
        last = np.minimum(last, np.asarray(self.shape) - 1)
        if np.any(last < first):
            return np.zeros((0, 3), dtype=np.int64)
        axes = [np.arange(a, b + 1) for a, b in zip(first, last, strict=True)]
        return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)

    def _refresh_frontier(self, changed_flat: np.ndarray) -> None:
        if changed_flat.size == 0:
            return
        coords = np.unravel_index(changed_flat, self.shape)
        around = [changed_flat] + [nb[ok] for ok, nb in self._six(changed_flat, coords)]
        cells = self.unique_flat(np.concatenate(around))
        self.frontier.reshape(-1)[cells] = self._is_frontier(cells)

    def _six(self, flat: np.ndarray, coords: tuple[np.ndarray, ...]
             ) -> list[tuple[np.ndarray, np.ndarray]]:
        """(inside, flat index) of each cell's six face neighbours, by index arithmetic."""
        strides = np.cumprod((1,) + self.shape[:0:-1])[::-1]  # C order
        out = []
        for axis in range(3):
            c, step = coords[axis], int(strides[axis])
            out.append((c > 0, flat - step))
            out.append((c < self.shape[axis] - 1, flat + step))
        return out

    def _is_frontier(self, flat: np.ndarray) -> np.ndarray:
        """Frontier status of the given cells (flat indices), from the current log-odds."""
        values = self.logodds.reshape(-1)
        mine = values[flat]
        unknown = (mine > self.model.free_at) & (mine < self.model.occupied_at)
        near_free = np.zeros(flat.size, dtype=bool)
        for ok, nb in self._six(flat, np.unravel_index(flat, self.shape)):
            # outside the grid: look at the cell itself, which is not free where it matters
            near_free |= values[np.where(ok, nb, flat)] <= self.model.free_at
        return unknown & near_free


def _shift(a: np.ndarray, axis: int, shift: int) -> np.ndarray:
    """out[..i..] = a[..i + shift..] along `axis`, False beyond the border."""
    out = np.zeros_like(a)
    n = a.shape[axis]
    src = [slice(None)] * a.ndim
    dst = [slice(None)] * a.ndim
    src[axis] = slice(max(0, shift), n + min(0, shift))
    dst[axis] = slice(max(0, -shift), n - max(0, shift))
    out[tuple(dst)] = a[tuple(src)]
    return out
