"""The sequencing problem of FLAP §3.2: views as weighted cell sets plus transition times.

Cells that the same views see are merged into one "atom" whose weight is the sum of their
-log(1 - p(c)); eq. 3 for any set of atoms is then 1 - exp(-sum of weights). Eq. 4, 5 and 8 are
evaluated here literally (with set union) as the reference the planners are checked against.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from avs_planner.flap.errors import FlapError


@dataclass(frozen=True, eq=False)
class SequencingProblem:
    """n views over m atoms: who sees what, atom weights, and seconds between views."""

    members: np.ndarray  # (n, m) bool: view k sees atom a
    weights: np.ndarray  # (m,) -log(1 - p(atom)) > 0
    start: np.ndarray  # (n,) t(L_0, s_k): from the robot's current state
    times: np.ndarray  # (n, n) t(s_i, s_j)

    @classmethod
    def build(
        cls,
        cells: Sequence[np.ndarray],
        log_miss: np.ndarray,
        start: np.ndarray,
        times: np.ndarray,
    ) -> SequencingProblem:
        """From each view's region cells, log(1 - p(c)) per region cell (TargetBelief) and
        the transition table's rows."""
        n = len(cells)
        start, times = np.asarray(start, dtype=float), np.asarray(times, dtype=float)
        if start.shape != (n,) or times.shape != (n, n):
            raise FlapError(f"{n} views need start times ({n},) and times ({n}, {n})")
        if n and (np.any(start <= 0) or np.any(times[~np.eye(n, dtype=bool)] <= 0)):
            raise FlapError("transition times must be positive (sensing takes time)")
        members, weights = _atoms(cells, -np.asarray(log_miss, dtype=float))
        return cls(members, weights, start, times)

    @property
    def size(self) -> int:
        return int(self.members.shape[0])

    def p_all(self) -> float:
        """p(V̂(S)): the probability that some view sees a target (eq. 2, 3)."""
        return float(-np.expm1(-self.weights.sum()))

    def p_view(self, view: int, seen: Sequence[int] = ()) -> float:
        """p(s | L) of eq. 5: the view's atoms not seen by the views in `seen`."""
        new = set(np.flatnonzero(self.members[view])) - _union(self, seen)
        return float(-np.expm1(-sum(self.weights[a] for a in new)))

    def p_sequence(self, sequence: Sequence[int]) -> float:
        """p(L) of eq. 8."""
        return float(-np.expm1(-sum(self.weights[a] for a in _union(self, sequence))))

    def expected_time(self, sequence: Sequence[int]) -> float:
        """E[T | L] of eq. 4: each transition counts while no earlier view found the target."""
        total, survive, last = 0.0, 1.0, None
        for k, view in enumerate(sequence):
            step = self.start[view] if last is None else self.times[last, view]
            total += survive * step
            survive *= 1.0 - self.p_view(view, sequence[:k])
            last = view
        return total

    def complete(self, sequence: Sequence[int], omega: float) -> bool:
        """Eq. 9: what views could still add, given L found nothing, is below omega."""
        return self.p_sequence(sequence) > 1.0 - (1.0 - self.p_all()) / (1.0 - omega)

    def subset(self, views: Sequence[int]) -> SequencingProblem:
        """The problem restricted to some views (atoms re-merged, unseen ones dropped)."""
        idx = np.asarray(views, dtype=np.int64)
        members = self.members[idx]
        keep = np.flatnonzero(members.any(axis=0))
        cells = [keep[np.flatnonzero(row[keep])] for row in members]
        log_miss = np.zeros(self.weights.size)
        log_miss[keep] = -self.weights[keep]
        return SequencingProblem.build(cells, log_miss, self.start[idx],
                                       self.times[np.ix_(idx, idx)])  # fmt: skip


def _union(problem: SequencingProblem, views: Sequence[int]) -> set[int]:
    if not len(views):
        return set()
    return set(np.flatnonzero(problem.members[list(views)].any(axis=0)).tolist())


def _atoms(cells: Sequence[np.ndarray], weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Group the cells with positive weight by the set of views that see them."""
    n = len(cells)
    if n == 0:
        return np.zeros((0, 0), dtype=bool), np.zeros(0)
    used = np.unique(np.concatenate([np.asarray(c, dtype=np.int64) for c in cells]))
    used = used[weight[used] > 0]
    column = np.full(weight.size, -1, dtype=np.int64)
    column[used] = np.arange(used.size)
    seen = np.zeros((n, used.size), dtype=bool)
    for k, c in enumerate(cells):
        col = column[np.asarray(c, dtype=np.int64)]
        seen[k, col[col >= 0]] = True
    signature = np.packbits(seen, axis=0).T
    _, first, group = np.unique(signature, axis=0, return_index=True, return_inverse=True)
    weights = np.bincount(group.reshape(-1), weights=weight[used], minlength=first.size)
    return seen[:, first], weights


def survival_threshold(problem: SequencingProblem, omega: float) -> float:
    """A plan is complete once its survival 1 - p(L) drops below this (eq. 9 rearranged)."""
    if not 0.0 < omega < 1.0:
        raise FlapError(f"omega must be in (0, 1), got {omega}")
    return math.exp(-float(problem.weights.sum())) / (1.0 - omega)
