"""Node bookkeeping of the Python search: the per-state Pareto set of (cost, probability).

A node carries its cost c and success probability p. Two paths to the same state are only
merged when one dominates the other in both c and p, because the better g = c + R(1 - p) now
need not be the better g later (the rest of the plan scales R(1 - p)). A new label that an
old one dominates is dropped; old labels the new one dominates are marked dead, so their
queue entries are skipped when popped. (The C core keeps the same sets in its own tables.)
"""

from __future__ import annotations


class _Labels:
    """Per-state Pareto set of (cost, probability, node) labels."""

    def __init__(self) -> None:
        self.by_state: dict[int, list[tuple[float, float, int]]] = {}

    def add(self, state: int, c: float, p: float, node: int, alive: list[bool]) -> bool:
        labels = self.by_state.get(state)
        if labels is None:
            self.by_state[state] = [(c, p, node)]
            return True
        for c0, p0, _ in labels:
            if c0 <= c and p0 >= p:
                return False
        kept = []
        for label in labels:
            if c <= label[0] and p >= label[1]:
                alive[label[2]] = False
            else:
                kept.append(label)
        kept.append((c, p, node))
        self.by_state[state] = kept
        return True
