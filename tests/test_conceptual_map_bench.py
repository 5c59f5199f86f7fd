"""The conceptual-map bench's junction-tree reference: pgmpy's BeliefPropagation on a
min-fill triangulation gives variable elimination's marginals, on small cliques."""

from __future__ import annotations

import warnings

import numpy as np

from bench.conceptual_map_bench import junction_tree_marginals, measure, random_building
from conceptual_map.conceptual.exact import exact_marginals, markov_network


def test_junction_tree_marginals_equal_variable_elimination():
    cmap = random_building(12, seed=3)
    cmap.update(cold=True)
    factors = cmap.factors(merged=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tree, largest = junction_tree_marginals(factors)
        exact = exact_marginals(factors)
    assert set(tree) == set(exact) == set(markov_network(factors).nodes())
    for variable, values in exact.items():
        np.testing.assert_allclose(tree[variable], values, atol=1e-9)
    assert 2 <= largest <= 4  # min-fill keeps the cliques small on these maps


def test_a_row_has_both_references():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        row = measure(6, exact_limit=6, repeats=1, seed=1)
    assert row.exact_ms is not None and row.jt_ms is not None
    assert row.max_error is not None and row.jt_max_error is not None
    assert abs(row.max_error - row.jt_max_error) < 1e-6  # ours against the same marginals


def test_junction_tree_marginals_on_a_100_room_map():
    """Beliefs of ~1e-13 there: pgmpy's calibrate() stopped early on them (its convergence
    test has an absolute tolerance) and 92 of 100 marginals came out wrong."""
    from pgmpy.inference import VariableElimination

    cmap = random_building(100, seed=0)
    cmap.update(cold=True)
    factors = cmap.factors(merged=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tree, _ = junction_tree_marginals(factors)
        inference = VariableElimination(markov_network(factors))
        for variable in sorted(tree)[::20]:
            values = inference.query([variable], show_progress=False).values
            np.testing.assert_allclose(tree[variable], values / values.sum(), atol=1e-9)
