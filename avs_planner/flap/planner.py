"""Expected-time view sequencing (FLAP eq. 4-9): branch and bound, greedy, brute force.

`plan_views` is the FLAP paper's planner: depth-first branch and bound that expands children in
order of utility p/t (eq. 6, Sarmiento et al.'s utility greedy), optionally drops strictly
dominated views (eq. 7, flag xi), branches only up to depth psi and only on children whose
utility is at least the best utility / phi, and stops a plan once it is complete (eq. 9, omega).
Its first dive is the greedy sequence, so it is anytime. Set differences only: each node keeps,
per view, the weight of the atoms it would still reveal, and subtracts what the chosen view
covers. xi, psi and phi give up optimality for speed; an instance small enough to search without
them within the node budget (`PlannerOptions.exact_nodes`) is searched exactly.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from enum import Enum

import numpy as np
from scipy import sparse

from avs_planner.flap.errors import FlapError
from avs_planner.flap.problem import SequencingProblem, survival_threshold

_EPS = 1e-12
_MEMO_CAP = 2_000_000  # partial plans remembered for exact duplicate pruning


class StopReason(Enum):
    """Why planning ended."""

    SEARCHED = "searched"  # every branch the options allow was searched (or bounded)
    NODE_LIMIT = "node_limit"
    TIME_LIMIT = "time_limit"
    DONE = "done"  # p(V̂(S)) < omega: nothing left worth looking for (the search is over)


@dataclass(frozen=True)
class PlannerOptions:
    """xi: prune dominated views; psi: branching depth; phi: branch factor; omega: eq. 9.

    deepen: search with branching depth 0 (the greedy plan), 1, 2, ... up to psi, each
    depth-first branch and bound starting from the best plan so far, so that a limit strikes
    in a deep search only after the alternatives for the first views were compared. Without
    it a depth-first search cut short by a limit has only varied the last branching levels:
    its first view, the only one a continual planner executes, is then the greedy one.

    exact_nodes: an instance whose tree of all view sequences has at most this many nodes
    (those with a positive gain; 8 views: 109,600) is searched exactly, with xi, psi and phi
    off. xi, psi and phi give up optimality to make big instances tractable (eq. 7 is
    Sarmiento et al.'s heuristic, not a safe rule: it can drop the view on the way to the
    others); a search that fits the default node budget (200,000) even without any pruning
    needs none of them. 0 keeps the heuristics at every size.
    """

    xi: bool = True
    psi: int = 6
    phi: float = 3.0
    omega: float = 0.05
    max_nodes: int | None = 200_000
    time_limit: float | None = None
    deepen: bool = True
    exact_nodes: int = 200_000

    def check(self) -> None:
        if self.psi < 0 or self.phi < 1.0:
            raise FlapError(f"need psi >= 0 and phi >= 1, got {self.psi}, {self.phi}")
        if self.exact_nodes < 0:
            raise FlapError(f"exact_nodes must be >= 0, got {self.exact_nodes}")
        if not 0.0 < self.omega < 1.0:
            raise FlapError(f"omega must be in (0, 1), got {self.omega}")


EXACT = PlannerOptions(xi=False, psi=10**9, phi=math.inf, max_nodes=None, deepen=False)
GREEDY = PlannerOptions(psi=0, exact_nodes=0)


def sequence_tree_size(views: int, cap: int | None = None) -> int:
    """Nodes of the tree of all sequences of distinct views (sum of n!/(n-k)!, k = 1..n),
    counted up to `cap` (the count stops growing once it passes the cap)."""
    total, level = 0, 1
    for k in range(views):
        level *= views - k
        total += level
        if cap is not None and total > cap:
            break
    return total


@dataclass(frozen=True)
class PlanResult:
    """A view sequence (problem indices), its E[T] (eq. 4) and p(L) (eq. 8), and the effort."""

    sequence: tuple[int, ...]
    expected_time: float
    probability: float
    nodes: int
    stop: StopReason
    seconds: float
    exact: bool = False  # searched without xi, psi, phi (the instance fits exact_nodes)

    # An empty sequence with an infinite expected time: a limit struck before the first
    # complete plan (the first dive is the greedy one, so give it at least its length).

    @property
    def next_view(self) -> int | None:
        """The view to go to now (continual planning executes only this one)."""
        return self.sequence[0] if self.sequence else None


def plan_views(problem: SequencingProblem, options: PlannerOptions | None = None) -> PlanResult:
    """Branch and bound over view sequences that minimise the expected search time."""
    options = options or PlannerOptions()
    options.check()
    return _BranchAndBound(problem, options).run()


def plan_greedy(problem: SequencingProblem, omega: float = 0.05) -> PlanResult:
    """The greedy baseline: always the next best view by utility p/t until complete."""
    return plan_views(problem, PlannerOptions(psi=0, omega=omega, exact_nodes=0))


class _Limit(Exception):
    """Raised inside the search when a node or time budget runs out."""


class _BranchAndBound:
    def __init__(self, problem: SequencingProblem, options: PlannerOptions):
        self.members = problem.members.astype(np.float64)
        useful = int(np.count_nonzero(self.members @ problem.weights > _EPS))
        self.exact = options.exact_nodes > 0 and (
            sequence_tree_size(useful, options.exact_nodes) <= options.exact_nodes)
        if self.exact:  # small enough to search every sequence: no heuristic pruning
            options = replace(options, xi=False, psi=max(useful, 1), phi=math.inf)
        self.p, self.o = problem, options
        self.atoms = [np.flatnonzero(row) for row in problem.members]
        self.overlaps: dict[int, sparse.csr_matrix] = {}
        self.columns: sparse.csc_matrix | None = None
        self.threshold = survival_threshold(problem, options.omega)
        off = np.where(np.eye(problem.size, dtype=bool), np.inf, problem.times)
        self.row_min = off.min(axis=1)  # fastest way on from each view
        self.t_min = float(self.row_min.min()) if problem.size > 1 else 0.0
        self.best: tuple[float, tuple[int, ...], float] = (math.inf, (), 0.0)
        self.nodes, self.path = 0, []
        self.memo: dict[tuple[frozenset[int], int], float] = {}
        self.psi = options.psi  # the branching depth of the current iteration
        self.cut = False  # whether the current iteration's psi cut off some branching
        self.depth = 0  # the deepest iteration run (PlanResult does not carry it)

    def run(self) -> PlanResult:
        began = time.perf_counter()
        self.deadline = None if self.o.time_limit is None else began + self.o.time_limit
        if self.p.size == 0 or self.p.p_all() < self.o.omega:
            return PlanResult((), 0.0, 0.0, 0, StopReason.DONE, time.perf_counter() - began,
                              self.exact)  # fmt: skip
        gain = self.members @ self.p.weights
        stop = StopReason.SEARCHED
        depths = range(self.o.psi + 1) if self.o.deepen else (self.o.psi,)
        try:
            for psi in depths:
                self.psi, self.cut, self.depth = psi, False, psi
                self.memo.clear()  # what lies below a node depends on psi
                self._visit(gain, self.p.weights.copy(), -1, 0.0, 1.0)
                if not self.cut:
                    break  # psi limited nothing: a deeper search would be this one again
        except _Limit as limit:
            stop = limit.args[0]
        cost, seq, survive = self.best
        return PlanResult(seq, cost, 1.0 - survive, self.nodes, stop,
                          time.perf_counter() - began, self.exact)  # fmt: skip

    def _visit(
        self, gain: np.ndarray, rest: np.ndarray, last: int, cost: float, survive: float
    ) -> None:
        """Extend the partial plan self.path: `gain` per view and `rest` per atom are the
        weights not yet seen, `cost` is E[T] so far and `survive` is 1 - p(L)."""
        self._count()
        if self._reached_cheaper(last, cost):
            return
        if survive < self.threshold:
            if cost < self.best[0]:
                self.best = (cost, tuple(self.path), survive)
            return
        row = self.p.start if last < 0 else self.p.times[last]
        g_max = float(gain.max())
        for view in self._children(gain, row, len(self.path)):
            step_cost = cost + survive * row[view]
            after = survive * math.exp(-gain[view])
            if step_cost + self._still_to_pay(view, after, g_max) >= self.best[0]:
                continue
            self.path.append(int(view))
            self._visit(*self._apply(gain, rest, view), int(view), step_cost, after)
            self.path.pop()

    def _reached_cheaper(self, last: int, cost: float) -> bool:
        """True if the same set of views, ending at the same view, was already reached at no
        more cost: the rest of the search from there is identical (same p(L)), so this
        ordering cannot win. Exact pruning; the table is capped to bound memory."""
        if len(self.path) < 2:
            return False
        key = (frozenset(self.path), last)
        seen = self.memo.get(key)
        if seen is not None and seen <= cost:
            return True
        if seen is not None or len(self.memo) < _MEMO_CAP:
            self.memo[key] = cost
        return False

    def _still_to_pay(self, view: int, survive: float, g_max: float) -> float:
        """Admissible bound on the rest of E[T]: no view gains more than g_max from now on,
        so at least K more steps are needed, each costing at least t_min while unfinished."""
        if survive < self.threshold:
            return 0.0
        if g_max <= _EPS:
            return math.inf
        steps = math.ceil(math.log(survive / self.threshold) / g_max)  # never too many
        decay = math.exp(-g_max)
        rest = (1.0 - decay ** (steps - 1)) / (1.0 - decay) if steps > 1 and decay < 1 else 0.0
        return survive * (self.row_min[view] + self.t_min * decay * rest)

    def _children(self, gain: np.ndarray, row: np.ndarray, depth: int) -> np.ndarray:
        """Views worth appending, best utility first (eq. 6, 7; psi and phi)."""
        cand = np.flatnonzero(gain > _EPS)
        if cand.size == 0:
            return cand
        p = -np.expm1(-gain[cand])
        t = row[cand]
        if self.o.xi:
            keep = ~_dominated(p, t)
            cand, p, t = cand[keep], p[keep], t[keep]
        util = p / t
        order = np.argsort(-util, kind="stable")
        if depth >= self.psi:
            self.cut = self.cut or cand.size > 1
            return cand[order[:1]]
        order = order[util[order] >= util[order[0]] / self.o.phi]
        return cand[order]

    def _apply(
        self, gain: np.ndarray, rest: np.ndarray, view: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Gains and unseen weights after `view` (set difference: only its atoms count)."""
        mine = self.atoms[view]
        gain = np.maximum(gain - self._overlap(view) @ rest[mine], 0.0)
        rest = rest.copy()
        rest[mine] = 0.0
        return gain, rest

    def _overlap(self, view: int) -> sparse.csr_matrix:
        """Which views share each of `view`'s atoms, sparse (n, atoms of view), built once."""
        if view not in self.overlaps:
            if self.columns is None:  # column slices of a CSC matrix are cheap
                self.columns = sparse.csc_matrix(self.p.members, dtype=np.float64)
            self.overlaps[view] = self.columns[:, self.atoms[view]].tocsr()
        return self.overlaps[view]

    def _count(self) -> None:
        self.nodes += 1
        if self.o.max_nodes is not None and self.nodes > self.o.max_nodes:
            raise _Limit(StopReason.NODE_LIMIT)
        if self.deadline is not None and self.nodes % 64 == 0:
            if time.perf_counter() > self.deadline:
                raise _Limit(StopReason.TIME_LIMIT)


def _dominated(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Eq. 7: views for which another has strictly higher p and strictly lower t."""
    order = np.argsort(t, kind="stable")
    ts, ps = t[order], p[order]
    best_before = np.maximum.accumulate(np.concatenate([[-np.inf], ps]))  # over ts[:k]
    faster = np.searchsorted(ts, ts, side="left")  # count of strictly smaller t
    out = np.empty(p.size, dtype=bool)
    out[order] = best_before[faster] > ps
    return out


def plan_exhaustive(problem: SequencingProblem, omega: float = 0.05) -> PlanResult:
    """Brute force: every sequence of views with positive gain, each ended at completion
    (eq. 9); seen cells as boolean unions, E[T] summed term by term as eq. 4 writes it.
    The reference the branch and bound is tested against; factorial in the view count."""
    began = time.perf_counter()
    if problem.size == 0 or problem.p_all() < omega:
        return PlanResult((), 0.0, 0.0, 0, StopReason.DONE, time.perf_counter() - began)
    walk = _Enumeration(problem, survival_threshold(problem, omega))
    walk.extend([], np.zeros(problem.weights.size, dtype=bool), 0.0, 1.0)
    seq = walk.best_sequence
    return PlanResult(seq, walk.best_cost, problem.p_sequence(seq), walk.count,
                      StopReason.SEARCHED, time.perf_counter() - began, True)  # fmt: skip


class _Enumeration:
    """Depth-first enumeration of all complete sequences, no pruning."""

    def __init__(self, problem: SequencingProblem, threshold: float):
        self.p, self.threshold = problem, threshold
        self.best_cost, self.best_sequence, self.count = math.inf, (), 0

    def extend(self, seq: list[int], seen: np.ndarray, cost: float, survive: float) -> None:
        self.count += 1
        if seq and survive < self.threshold:
            if cost < self.best_cost:
                self.best_cost, self.best_sequence = cost, tuple(seq)
            return
        for view in range(self.p.size):
            new = self.p.members[view] & ~seen
            if view in seq or not new.any():
                continue
            step = self.p.start[view] if not seq else self.p.times[seq[-1], view]
            p_new = -math.expm1(-float(self.p.weights[new].sum()))  # eq. 3 and 5
            seq.append(view)
            self.extend(seq, seen | new, cost + survive * step, survive * (1.0 - p_new))
            seq.pop()
