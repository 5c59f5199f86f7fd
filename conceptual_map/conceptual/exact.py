"""Exact marginals with pgmpy (reference for loopy BP in tests and the benchmark)."""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
from pgmpy.factors.discrete import DiscreteFactor
from pgmpy.inference import VariableElimination
from pgmpy.models import DiscreteMarkovNetwork


def markov_network(factors: Sequence[DiscreteFactor]) -> DiscreteMarkovNetwork:
    """A checked pgmpy Markov network holding copies of `factors`."""
    network = DiscreteMarkovNetwork()
    for factor in factors:
        scope = factor.scope()
        network.add_nodes_from(scope)
        if len(scope) == 2:
            network.add_edge(*scope)
    network.add_factors(*(factor.copy() for factor in factors))
    network.check_model()
    return network


def exact_marginals(factors: Sequence[DiscreteFactor]) -> dict[str, np.ndarray]:
    """Normalised single-variable marginals by variable elimination, one query per variable.

    pgmpy's VariableElimination returns unnormalised results on Markov networks, so we
    normalise here.
    """
    network = markov_network(factors)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        inference = VariableElimination(network)
        marginals = {}
        for variable in network.nodes():
            values = inference.query([variable], show_progress=False).values
            marginals[variable] = values / values.sum()
    return marginals
