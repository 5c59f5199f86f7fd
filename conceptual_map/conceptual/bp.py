"""Loopy belief propagation (sum-product, damped) on a pairwise Markov network, vectorised.

pgmpy has no loopy BP, so this is ours; the network is built from pgmpy `DiscreteFactor`s
(`PairwiseMRF.from_factors`) and checked against pgmpy's exact inference in the tests.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import sparse

from conceptual_map.conceptual.errors import ConceptualError

if TYPE_CHECKING:  # factors are read, never made, here: pgmpy is not imported
    from pgmpy.factors.discrete import DiscreteFactor

_TINY = 1e-300


class BPStatus(enum.Enum):
    """How a BP run ended."""

    CONVERGED = "converged"
    MAX_ITERATIONS = "max_iterations"


@dataclass(frozen=True)
class BPSettings:
    """Damping in [0, 1) mixes the old message in; tolerance bounds the largest message change."""

    damping: float = 0.3
    tolerance: float = 1e-8
    max_iterations: int = 500


@dataclass(frozen=True)
class BPResult:
    """Marginals `(n, K)` in node order, plus the final messages for a warm start."""

    status: BPStatus
    marginals: np.ndarray
    iterations: int
    max_delta: float
    messages: np.ndarray


@dataclass(frozen=True)
class PairwiseMRF:
    """Nodes with K states each; `unary (n, K)`; `edges (E, 2)`; `pairwise[e][x_a, x_b]`."""

    unary: np.ndarray
    edges: np.ndarray
    pairwise: np.ndarray

    @property
    def n_nodes(self) -> int:
        return int(self.unary.shape[0])

    @staticmethod
    def from_factors(factors: Sequence[DiscreteFactor]) -> tuple[PairwiseMRF, list[str]]:
        """Multiply unary and pairwise factors into a pairwise MRF; returns it and node names."""
        names = _variables_in_order(factors)
        index = {name: i for i, name in enumerate(names)}
        states = _common_cardinality(factors)
        unary = np.ones((len(names), states))
        pair_values: dict[tuple[int, int], np.ndarray] = {}
        for factor in factors:
            ids = [index[v] for v in factor.scope()]
            if len(ids) == 1:
                unary[ids[0]] *= factor.values
            elif len(ids) == 2:
                values = factor.values if ids[0] < ids[1] else factor.values.T
                key = (min(ids), max(ids))
                pair_values[key] = pair_values.get(key, np.ones((states, states))) * values
            else:
                raise ConceptualError(f"factor over {factor.scope()} is not unary or pairwise")
        edges = np.array(sorted(pair_values), dtype=np.int64).reshape(-1, 2)
        pairwise = np.array([pair_values[tuple(e)] for e in edges]).reshape(-1, states, states)
        return PairwiseMRF(unary, edges, pairwise), names


def _variables_in_order(factors: Sequence[DiscreteFactor]) -> list[str]:
    seen: dict[str, None] = {}
    for factor in factors:
        seen.update(dict.fromkeys(factor.scope()))
    return list(seen)


def _common_cardinality(factors: Sequence[DiscreteFactor]) -> int:
    cards = {int(c) for factor in factors for c in factor.cardinality}
    if len(cards) != 1:
        raise ConceptualError(f"all variables need the same number of states, got {sorted(cards)}")
    return cards.pop()


def loopy_bp(
    mrf: PairwiseMRF, settings: BPSettings | None = None, init: np.ndarray | None = None
) -> BPResult:
    """Flooding-schedule sum-product; exact on trees, approximate on loopy graphs.

    `init` (2E, K) warm-starts the messages (order: edges a->b, then b->a); uniform otherwise.
    """
    settings = settings or BPSettings()
    if not 0.0 <= settings.damping < 1.0:
        raise ConceptualError(f"damping must be in [0, 1), got {settings.damping}")
    unary = _normalise(mrf.unary)
    log_unary = np.log(unary, where=unary > 0, out=np.full(unary.shape, -np.inf))
    plan = _MessagePlan.of(mrf)
    if plan.n_messages == 0:
        return BPResult(BPStatus.CONVERGED, _normalise(mrf.unary), 0, 0.0, np.empty((0, 0)))
    messages = _initial_messages(plan, mrf.unary.shape[1], init)
    delta, iteration = np.inf, 0
    while delta > settings.tolerance and iteration < settings.max_iterations:
        new = plan.step(log_unary, messages)
        new = (1.0 - settings.damping) * new + settings.damping * messages
        delta = float(np.abs(new - messages).max())
        messages, iteration = new, iteration + 1
    status = BPStatus.CONVERGED if delta <= settings.tolerance else BPStatus.MAX_ITERATIONS
    marginals = _softmax(plan.log_beliefs(log_unary, messages))
    return BPResult(status, marginals, iteration, delta, messages)


@dataclass(frozen=True)
class _MessagePlan:
    """Index arrays for the 2E directed messages: message d goes src[d] -> dst[d]."""

    src: np.ndarray
    reverse: np.ndarray
    potentials: np.ndarray
    incoming: sparse.csr_matrix
    shared: np.ndarray | None

    @property
    def n_messages(self) -> int:
        return int(self.src.shape[0])

    @staticmethod
    def of(mrf: PairwiseMRF) -> _MessagePlan:
        a, b = mrf.edges[:, 0], mrf.edges[:, 1]
        n_edges = a.shape[0]
        src, dst = np.concatenate([a, b]), np.concatenate([b, a])
        reverse = np.concatenate([np.arange(n_edges) + n_edges, np.arange(n_edges)])
        potentials = np.concatenate([mrf.pairwise, mrf.pairwise.transpose(0, 2, 1)])
        incoming = sparse.csr_matrix(
            (np.ones(2 * n_edges), (dst, np.arange(2 * n_edges))), shape=(mrf.n_nodes, 2 * n_edges)
        )
        return _MessagePlan(src, reverse, potentials, incoming, _shared_symmetric(mrf.pairwise))

    def log_beliefs(self, log_unary: np.ndarray, messages: np.ndarray) -> np.ndarray:
        return log_unary + self.incoming @ np.log(np.maximum(messages, _TINY))

    def step(self, log_unary: np.ndarray, messages: np.ndarray) -> np.ndarray:
        """One synchronous update of every message from the current ones."""
        log_messages = np.log(np.maximum(messages, _TINY))
        log_b = log_unary + self.incoming @ log_messages
        cavity = log_b[self.src] - log_messages[self.reverse]
        weights = _softmax(cavity)
        if self.shared is not None:
            return _normalise(weights @ self.shared)
        return _normalise(np.einsum("dk,dkl->dl", weights, self.potentials))


def _shared_symmetric(pairwise: np.ndarray) -> np.ndarray | None:
    """The one symmetric potential every edge uses (phi_rc in the chain graph), else None."""
    if pairwise.shape[0] == 0:
        return None
    first = pairwise[0]
    if np.array_equal(first, first.T) and (pairwise == first).all():
        return first
    return None


def _initial_messages(plan: _MessagePlan, states: int, init: np.ndarray | None) -> np.ndarray:
    uniform = np.full((plan.n_messages, states), 1.0 / states)
    if init is None:
        return uniform
    if init.shape != uniform.shape:
        raise ConceptualError(f"warm-start messages have shape {init.shape}, need {uniform.shape}")
    return _normalise(np.maximum(init, _TINY))


def _normalise(values: np.ndarray) -> np.ndarray:
    """Rows scaled to sum 1; an all-zero row (contradiction) becomes uniform."""
    sums = values.sum(axis=1, keepdims=True)
    if sums.min() > 0:
        return values / sums
    uniform = np.full_like(values, 1.0 / values.shape[1])
    return np.divide(values, sums, out=uniform, where=sums > 0)


def _softmax(log_values: np.ndarray) -> np.ndarray:
    top = log_values.max(axis=1, keepdims=True)
    if not np.isfinite(top).all():
        top = np.where(np.isfinite(top), top, 0.0)
    return _normalise(np.exp(log_values - top))
