"""Loopy BP against pgmpy's exact inference on random trees, rings and grids."""

import networkx as nx
import numpy as np
import pytest
from pgmpy.factors.discrete import DiscreteFactor

from conceptual_map.conceptual import (
    BPSettings,
    BPStatus,
    ConceptualError,
    PairwiseMRF,
    loopy_bp,
)
from conceptual_map.conceptual.exact import exact_marginals


def _random_factors(graph: nx.Graph, states: int, rng: np.random.Generator,
                    low: float = 0.2) -> list[DiscreteFactor]:
    """Random positive unary and pairwise potentials on the nodes/edges of `graph`."""
    names = {node: f"x{i}" for i, node in enumerate(graph.nodes)}
    factors = [DiscreteFactor([names[n]], [states], rng.uniform(0.05, 1.0, states))
               for n in graph.nodes]
    factors += [DiscreteFactor([names[a], names[b]], [states, states],
                               rng.uniform(low, 1.0, (states, states)))
                for a, b in graph.edges]
    return factors


def _max_error(factors: list[DiscreteFactor], settings: BPSettings | None = None) -> float:
    mrf, names = PairwiseMRF.from_factors(factors)
    result = loopy_bp(mrf, settings or BPSettings(tolerance=1e-12))
    assert result.status is BPStatus.CONVERGED
    exact = exact_marginals(factors)
    return max(float(np.abs(result.marginals[i] - exact[name]).max())
               for i, name in enumerate(names))


@pytest.mark.parametrize("seed", range(8))
def test_random_trees_match_exact_marginals(seed):
    rng = np.random.default_rng(seed)
    tree = nx.random_labeled_tree(int(rng.integers(2, 25)), seed=seed)
    factors = _random_factors(tree, int(rng.integers(2, 7)), rng, low=0.01)
    assert _max_error(factors) <= 1e-6


@pytest.mark.parametrize("seed", range(6))
def test_random_rings_are_close_to_exact(seed):
    rng = np.random.default_rng(100 + seed)
    ring = nx.cycle_graph(int(rng.integers(3, 13)))
    assert _max_error(_random_factors(ring, int(rng.integers(2, 7)), rng)) <= 0.02


@pytest.mark.parametrize("seed", range(6))
def test_random_grids_are_close_to_exact(seed):
    rng = np.random.default_rng(200 + seed)
    rows, cols = int(rng.integers(2, 5)), int(rng.integers(2, 5))
    grid = nx.grid_2d_graph(rows, cols)
    assert _max_error(_random_factors(grid, int(rng.integers(2, 5)), rng)) <= 0.02


def test_damping_does_not_change_the_tree_fixed_point():
    rng = np.random.default_rng(7)
    factors = _random_factors(nx.random_labeled_tree(12, seed=7), 4, rng)
    for damping in (0.0, 0.5, 0.9):
        assert _max_error(factors, BPSettings(damping=damping, tolerance=1e-12,
                                              max_iterations=5000)) <= 1e-6


def test_warm_start_reaches_the_same_marginals_in_fewer_iterations():
    rng = np.random.default_rng(3)
    mrf, _ = PairwiseMRF.from_factors(_random_factors(nx.grid_2d_graph(3, 3), 3, rng))
    cold = loopy_bp(mrf, BPSettings(tolerance=1e-10))
    warm = loopy_bp(mrf, BPSettings(tolerance=1e-10), init=cold.messages)
    np.testing.assert_allclose(warm.marginals, cold.marginals, atol=1e-8)
    assert warm.iterations < cold.iterations


def test_iteration_cap_is_reported():
    rng = np.random.default_rng(4)
    mrf, _ = PairwiseMRF.from_factors(_random_factors(nx.cycle_graph(6), 3, rng))
    result = loopy_bp(mrf, BPSettings(tolerance=0.0, max_iterations=3))
    assert result.status is BPStatus.MAX_ITERATIONS
    assert result.iterations == 3


def test_graph_without_edges_returns_normalised_unaries():
    factors = [DiscreteFactor(["a"], [2], [1.0, 3.0]), DiscreteFactor(["b"], [2], [2.0, 2.0])]
    mrf, names = PairwiseMRF.from_factors(factors)
    result = loopy_bp(mrf)
    assert names == ["a", "b"]
    np.testing.assert_allclose(result.marginals, [[0.25, 0.75], [0.5, 0.5]])


def test_zero_potentials_are_handled():
    factors = [DiscreteFactor(["a"], [2], [0.0, 1.0]),
               DiscreteFactor(["a", "b"], [2, 2], [[1.0, 0.0], [0.0, 1.0]])]
    mrf, _ = PairwiseMRF.from_factors(factors)
    np.testing.assert_allclose(loopy_bp(mrf).marginals, [[0.0, 1.0], [0.0, 1.0]], atol=1e-7)


def test_bad_inputs_raise_conceptual_errors():
    triple = DiscreteFactor(["a", "b", "c"], [2, 2, 2], np.ones(8))
    with pytest.raises(ConceptualError, match="not unary or pairwise"):
        PairwiseMRF.from_factors([triple])
    mixed = [DiscreteFactor(["a"], [2], [1, 1]), DiscreteFactor(["b"], [3], [1, 1, 1])]
    with pytest.raises(ConceptualError, match="same number of states"):
        PairwiseMRF.from_factors(mixed)
    mrf, _ = PairwiseMRF.from_factors([DiscreteFactor(["a", "b"], [2, 2], np.ones(4))])
    with pytest.raises(ConceptualError, match="damping"):
        loopy_bp(mrf, BPSettings(damping=1.0))
    with pytest.raises(ConceptualError, match="warm-start"):
        loopy_bp(mrf, init=np.ones((5, 2)))
