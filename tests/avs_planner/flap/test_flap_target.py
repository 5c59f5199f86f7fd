"""Eq. 1-3 by hand on a tiny voxel map: per-cell probability, p(C) and p(V̂(S))."""

import math

import numpy as np
import pytest

from avs_planner.flap.errors import FlapError
from avs_planner.flap.target import TargetBelief, TargetVolume, uniform_volumes
from conceptual_map.metric import Rays, VoxelMap


def tiny_map() -> VoxelMap:
    """1 x 1 x 1 m at 0.25 m: 4 x 4 x 4 cells, all unknown."""
    return VoxelMap(origin=(0.0, 0.0, 0.0), size=(1.0, 1.0, 1.0), resolution=0.25)


def test_eq1_each_cell_carries_an_equal_share_of_the_volume() -> None:
    # cells with centres in [0, 0.5] x [0, 0.5] x [0, 0.25]: 2 x 2 x 1 = 4 cells
    belief = TargetBelief(tiny_map(), [TargetVolume((0, 0, 0), (0.5, 0.5, 0.25), 0.2)])
    assert belief.size == 4
    expected = 1.0 - 0.8 ** (1.0 / 4.0)
    assert np.allclose(belief.probabilities(), expected)
    # eq. 3 over the whole volume gives back P_i, over two cells 1 - 0.8^(1/2)
    assert belief.p_cells(np.arange(4)) == pytest.approx(0.2)
    assert belief.p_cells(np.array([0, 3])) == pytest.approx(1.0 - math.sqrt(0.8))
    assert belief.p_cells(np.array([0, 0, 3])) == pytest.approx(1.0 - math.sqrt(0.8))


def test_eq2_union_of_views_and_two_independent_volumes() -> None:
    volumes = [TargetVolume((0, 0, 0), (0.5, 0.5, 0.25), 0.2),
               TargetVolume((0.75, 0.75, 0.75), (1.0, 1.0, 1.0), 0.5)]  # fmt: skip
    belief = TargetBelief(tiny_map(), volumes)
    assert belief.size == 5
    single = int(np.flatnonzero(belief.probabilities() > 0.4)[0])
    assert belief.probabilities()[single] == pytest.approx(0.5)  # N = 1: p(c) = P
    views = [np.array([0, 1]), np.array([1, single])]
    # union {0, 1, single}: 1 - 0.8^(2/4) * 0.5
    assert belief.p_views(views) == pytest.approx(1.0 - math.sqrt(0.8) * 0.5)
    assert belief.p_views([]) == 0.0


def test_overlapping_volumes_act_independently() -> None:
    box = ((0, 0, 0), (0.25, 0.25, 0.25))  # one cell
    belief = TargetBelief(tiny_map(), uniform_volumes([box, box], 0.2))
    assert belief.size == 1
    assert belief.probabilities()[0] == pytest.approx(1.0 - 0.8 * 0.8)


def test_seen_cells_drop_to_zero_and_the_count_n_stays() -> None:
    voxels = tiny_map()
    belief = TargetBelief(voxels, [TargetVolume((0, 0, 0), (0.5, 0.5, 0.25), 0.2)])
    # two rays along x through the row y = 0.125, z = 0.125 make those cells free
    start, end = np.array([[0.01, 0.125, 0.125]] * 2), np.array([[0.99, 0.125, 0.125]] * 2)
    for _ in range(3):
        voxels.integrate_rays(Rays(start, end, np.array([False, False])))
    belief.refresh(voxels)
    p = belief.probabilities()
    assert int((p == 0).sum()) == 2  # the cells at x = 0.125, 0.375 on that row
    assert np.allclose(p[p > 0], 1.0 - 0.8 ** 0.25)
    belief.mark_seen(np.flatnonzero(p > 0)[:1])
    assert belief.p_cells(np.arange(4)) == pytest.approx(1.0 - 0.8 ** 0.25)


@pytest.mark.parametrize("volume", [
    TargetVolume((0, 0, 0), (1, 1, 1), 1.0),
    TargetVolume((0, 0, 0), (1, 1, 1), -0.1),
    TargetVolume((1, 0, 0), (0, 1, 1), 0.2),
])  # fmt: skip
def test_bad_volumes_are_flap_errors(volume: TargetVolume) -> None:
    with pytest.raises(FlapError):
        TargetBelief(tiny_map(), [volume])


def test_a_volume_outside_the_map_is_an_error() -> None:
    with pytest.raises(FlapError, match="no cell"):
        TargetBelief(tiny_map(), [TargetVolume((5, 5, 5), (6, 6, 6), 0.2)])
