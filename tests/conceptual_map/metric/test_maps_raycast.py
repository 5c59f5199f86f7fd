"""The vectorised traversal visits exactly the cells of the per-ray reference walk."""

import numpy as np
import pytest

from conceptual_map.metric.raycast import traverse, traverse_reference


@pytest.mark.parametrize("dim", [2, 3])
def test_traverse_matches_reference_walk(dim: int) -> None:
    rng = np.random.default_rng(dim)
    starts = rng.uniform(-30, 30, (300, dim))
    ends = rng.uniform(-30, 30, (300, dim))
    ends[:40] = starts[:40] + rng.uniform(-0.7, 0.7, (40, dim))  # short rays inside one cell
    ends[40:60, 0] = starts[40:60, 0]  # axis-parallel rays
    rays, cells = traverse(starts, ends)
    for i in range(starts.shape[0]):
        got = [tuple(c) for c in cells[rays == i].tolist()]
        want = traverse_reference(starts[i], ends[i])
        assert got == want, f"ray {i}"


def test_traverse_orders_cells_from_start_to_end() -> None:
    rays, cells = traverse(np.array([[0.5, 0.5]]), np.array([[3.5, 0.5]]))
    assert cells.tolist() == [[0, 0], [1, 0], [2, 0], [3, 0]]
    assert rays.tolist() == [0, 0, 0, 0]


def test_traverse_of_no_rays_is_empty() -> None:
    rays, cells = traverse(np.zeros((0, 3)), np.zeros((0, 3)))
    assert rays.shape == (0,) and cells.shape == (0, 3)
