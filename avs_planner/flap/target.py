"""Target probability per cell (FLAP eq. 1-3) over the cells of the target volumes.

Each volume V_i holds the target with probability P_i; its N_i cells share it equally and
independently, p(c) = 1 - (1 - P_i)^(1/N_i) while c is unknown and 0 once seen (eq. 1). Kept as
log(1 - p) per cell so that eq. 3 over a set of cells is one sum.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from avs_planner.flap.errors import FlapError
from conceptual_map.metric import CellState, VoxelMap


@dataclass(frozen=True)
class TargetVolume:
    """A box [lo, hi] (world metres) that holds the target with probability P_i (the FLAP
    paper: 0.2)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    probability: float = 0.2
    name: str = ""

    def check(self) -> None:
        """Raise FlapError unless the box is ordered and 0 <= P_i < 1."""
        if len(self.lo) != 3 or len(self.hi) != 3:
            raise FlapError(f"target volume {self.name!r}: lo and hi need three numbers each")
        if any(h < lo for lo, h in zip(self.lo, self.hi, strict=True)):
            raise FlapError(f"target volume {self.name!r}: need lo <= hi in x, y, z")
        if not 0.0 <= self.probability < 1.0:
            raise FlapError(
                f"target volume {self.name!r}: probability must be in [0, 1), "
                f"got {self.probability}"
            )


def uniform_volumes(
    boxes: Iterable[tuple[tuple[float, float, float], tuple[float, float, float]]],
    probability: float = 0.2,
) -> list[TargetVolume]:
    """Volumes that all carry the same P_i (the FLAP paper's experiments: 0.2 each)."""
    return [TargetVolume(lo, hi, probability, f"volume{k}") for k, (lo, hi) in enumerate(boxes)]


class TargetBelief:
    """The cells of the search region with their log(1 - p(c)) and whether each is unknown."""

    def __init__(self, voxels: VoxelMap, volumes: Sequence[TargetVolume]):
        if not volumes:
            raise FlapError("a search region needs at least one target volume")
        for volume in volumes:
            volume.check()
        self.volumes = tuple(volumes)
        self.centres, self._log_miss, self.volume_cells = _region_cells(voxels, self.volumes)
        self.unknown = np.ones(self.size, dtype=bool)
        self.refresh(voxels)

    @property
    def size(self) -> int:
        """Number of distinct cells over all volumes."""
        return int(self.centres.shape[0])

    def flat_indices(self, voxels: VoxelMap) -> np.ndarray:
        """Flat voxel indices of the region's cells in `voxels` (which may have grown)."""
        return np.ravel_multi_index(tuple(voxels.to_cell(self.centres).T), voxels.shape)

    def refresh(self, voxels: VoxelMap) -> None:
        """Take the cells the map now knows as seen (what the views actually observed)."""
        self.unknown = voxels.states_at(self.flat_indices(voxels)) == CellState.UNKNOWN

    def mark_seen(self, cells: np.ndarray) -> None:
        """Cells (region indices) that a view observed: their probability drops to 0."""
        self.unknown[np.asarray(cells, dtype=np.int64)] = False

    def log_miss(self) -> np.ndarray:
        """log(1 - p(c)) per region cell (0 for cells already seen)."""
        return np.where(self.unknown, self._log_miss, 0.0)

    def probabilities(self) -> np.ndarray:
        """p(c) per region cell (eq. 1)."""
        return -np.expm1(self.log_miss())

    def p_cells(self, cells: np.ndarray) -> float:
        """Probability of seeing a target among the given cells (eq. 3)."""
        cells = np.unique(np.asarray(cells, dtype=np.int64))
        return float(-np.expm1(self.log_miss()[cells].sum()))

    def p_views(self, view_cells: Iterable[np.ndarray]) -> float:
        """p(V̂(S)): probability of seeing a target with all views together (eq. 2 and 3)."""
        parts = [np.asarray(c, dtype=np.int64) for c in view_cells]
        if not parts:
            return 0.0
        return self.p_cells(np.concatenate(parts))

    def unknown_lookup(self, voxels: VoxelMap) -> np.ndarray:
        """Map-sized int32 array: region index of each unknown region cell, -1 elsewhere."""
        lut = np.full(voxels.logodds.size, -1, dtype=np.int32)
        flat = self.flat_indices(voxels)
        keep = self.unknown
        lut[flat[keep]] = np.nonzero(keep)[0].astype(np.int32)
        return lut


def _region_cells(
    voxels: VoxelMap, volumes: Sequence[TargetVolume]
) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """Distinct cell centres over all volumes, their summed log(1 - p) (eq. 1, volumes may
    overlap and then act independently), and each volume's region indices."""
    per_volume = [voxels.cells_in_box(v.lo, v.hi) for v in volumes]
    if all(c.shape[0] == 0 for c in per_volume):
        raise FlapError("the target volumes hold no cell of the voxel map")
    cells, inverse = np.unique(np.concatenate(per_volume), axis=0, return_inverse=True)
    log_miss = np.zeros(cells.shape[0])
    members, start = [], 0
    for volume, part in zip(volumes, per_volume, strict=True):
        index = inverse.reshape(-1)[start : start + part.shape[0]]
        start += part.shape[0]
        if part.shape[0]:
            log_miss[index] += np.log1p(-volume.probability) / part.shape[0]
        members.append(index)
    return voxels.to_world(cells), log_miss, members
