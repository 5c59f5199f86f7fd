"""A task's fact table cut down to the facts its reachable actions, rules and goal use.

The grounding structure numbers every atom of every statically possible ground action; on
IPC tetris that is 37,224 facts of which the 9,456 reachable actions read or change 928. A
state is a bitset over the table and the heuristics loop over it, so the search paid for
36,000 facts it never looks at. When most facts are unused, the task is renumbered
(monotonically: the order of facts, and so every tie-break, is kept); the structure and its
cache are untouched, and the renumbered pieces are kept with the action table they belong to.
"""

from __future__ import annotations

import operator
from collections.abc import Iterator, Sequence
from dataclasses import replace
from typing import overload

import numpy as np

from avs_planner.cp.task import GroundAction, GroundTask, TaskArrays

MIN_FACTS = 4096  # smaller tables are left as they are
MAX_USED_SHARE = 0.25  # renumber when at most this share of the facts is used


def bits_to_ids(bits: int, n: int) -> np.ndarray:
    """Fact ids set in a Python int bitset over n facts."""
    if not bits:
        return np.zeros(0, dtype=np.int64)
    raw = np.frombuffer(bits.to_bytes(n // 8 + 1, "little"), dtype=np.uint8)
    return np.flatnonzero(np.unpackbits(raw, bitorder="little"))


class _Remap:
    """Old fact id -> new fact id (-1: dropped)."""

    def __init__(self, used: np.ndarray, n: int):
        self.n = n
        self.new_of = np.full(n, -1, dtype=np.int64)
        self.new_of[used] = np.arange(len(used))
        self._list = self.new_of.tolist()

    def bits(self, bits: int) -> int:
        if not bits:
            return 0
        new = self.new_of[bits_to_ids(bits, self.n)]
        out = 0
        for i in new[new >= 0].tolist():
            out |= 1 << i
        return out

    def ids(self, ids: Sequence[int]) -> tuple[int, ...]:
        table = self._list
        return tuple(table[i] for i in ids if table[i] >= 0)

    def matrix(self, matrix: np.ndarray) -> np.ndarray:
        out = matrix.copy()
        valid = out >= 0
        out[valid] = self.new_of[out[valid]]
        return out


class CompactActions(Sequence[GroundAction]):
    """An action table read through a renumbering of its facts (built on first access)."""

    __slots__ = ("_table", "_remap", "_built", "memo")

    def __init__(self, table: Sequence[GroundAction], remap: _Remap):
        self._table = table
        self._remap = remap
        self._built: dict[int, GroundAction] = {}
        self.memo: dict[str, object] = {}

    def __len__(self) -> int:
        return len(self._table)

    @property
    def table(self) -> Sequence[GroundAction]:
        """The action table over the structure's fact ids that this one renumbers."""
        return self._table

    @overload
    def __getitem__(self, i: int) -> GroundAction: ...

    @overload
    def __getitem__(self, i: slice) -> tuple[GroundAction, ...]: ...

    def __getitem__(self, i):
        if isinstance(i, slice):
            return tuple(self.take(range(len(self)))[i])
        i, n = operator.index(i), len(self)
        if not -n <= i < n:
            raise IndexError("action index out of range")
        return self.take([i % n])[0]

    def __iter__(self) -> Iterator[GroundAction]:
        return iter(self.take(range(len(self))))

    def __repr__(self) -> str:
        return f"CompactActions({len(self)} actions)"

    def take(self, indices) -> list[GroundAction]:
        indices = [operator.index(i) for i in indices]
        built = self._built
        missing = [i for i in indices if i not in built]
        if missing:
            r = self._remap
            for a in self._table.take(missing):
                built[a.index] = a._replace(
                    pre=r.bits(a.pre), pre_neg=r.bits(a.pre_neg), add=r.bits(a.add),
                    delete=r.bits(a.delete), pre_facts=r.ids(a.pre_facts),
                    add_facts=r.ids(a.add_facts),
                    clauses=tuple((r.bits(p), r.bits(q)) for p, q in a.clauses))
        return [built[i] for i in indices]

    def find(self, name: str, args: Sequence[str]) -> GroundAction | None:
        found = self._table.find(name, args)
        return None if found is None else self.take([found.index])[0]


def _used(task: GroundTask) -> np.ndarray:
    n = len(task.facts)
    arrays = task.arrays
    used = np.zeros(n + 2, dtype=bool)
    for matrix in (arrays.pre, arrays.pre_neg, arrays.add, arrays.delete):
        used[matrix[matrix >= 0]] = True
    used = used[:n]
    # one pass over the union: unpacking each clause's bitset alone cost O(facts) per
    # bitset (67,586 of them, 2.2 s, on a generated 320-place building)
    union = task.goal | task.goal_neg
    for bits in {b for row in arrays.clauses.values() for pair in row for b in pair}:
        union |= bits
    used[bits_to_ids(union, n)] = True
    if task.axioms is not None:
        used[sorted(task.axioms.facts())] = True
    return np.flatnonzero(used)


def compact(task: GroundTask) -> GroundTask:
    """The task over the facts it uses, or the task itself when that saves little. The
    renumbered pieces are kept in the action table's memo, so replans reuse them (and what
    consumers keep with them: the native core's packed task)."""
    n = len(task.facts)
    memo = getattr(task.actions, "memo", None)
    if task.arrays is None or memo is None or n < MIN_FACTS:
        return task
    # the goal's facts are kept too, and the rules' (a goal compiled to rules has its own)
    key = (task.goal, task.goal_neg, len(task.facts))
    hit = memo.get("compact")
    if hit is None or hit[0] != key or hit[2] is not task.axioms:
        used = _used(task)
        pieces = _pieces(task, used) if len(used) <= MAX_USED_SHARE * n else ()
        hit = memo["compact"] = (key, pieces, task.axioms)
    hit = hit[1]
    if not hit:
        return task
    remap, facts, fact_index, actions, arrays, axioms = hit
    return replace(task, facts=facts, fact_index=fact_index, actions=actions, arrays=arrays,
                   init=remap.bits(task.init), goal=remap.bits(task.goal),
                   goal_neg=remap.bits(task.goal_neg), axioms=axioms)


def _pieces(task: GroundTask, used: np.ndarray) -> tuple:
    remap = _Remap(used, len(task.facts))
    facts = tuple(task.facts[i] for i in used.tolist())
    a = task.arrays
    arrays = TaskArrays(
        pre=remap.matrix(a.pre), pre_neg=remap.matrix(a.pre_neg), add=remap.matrix(a.add),
        delete=remap.matrix(a.delete), cost=a.cost, probability=a.probability,
        clauses={i: tuple((remap.bits(p), remap.bits(q)) for p, q in row)
                 for i, row in a.clauses.items()},
        arg_ids=a.arg_ids, objects=a.objects,
    )
    fact_index = {atom: i for i, atom in enumerate(facts)}
    axioms = None if task.axioms is None else task.axioms.remap(remap.new_of.tolist())
    return remap, facts, fact_index, CompactActions(task.actions, remap), arrays, axioms
