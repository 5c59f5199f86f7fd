"""The grounding structure itself: `GroundStructure`, its per-schema `_Block`s, and the
per-row view of a ground action that the tasks read.

A structure is what `structure.build_structure` returns and `GroundingCache` keeps per domain,
objects and static atoms: the fact table and every statically possible ground action as rows
of fact-id arrays. Building it (joins, compiled conditions, numbering) is `structure.py`'s
job; this module holds only the result and how one reads it (labels, row tuples built once).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from avs_planner.cp.encoding import AtomSpace, Columns
from avs_planner.cp.fact_rows import _row_masks, bitset, fact_matrix
from avs_planner.cp.schema import LiftedSchema
from avs_planner.cp.task import Atom

_FEW_ROWS = 64  # up to this many rows are built from Python lists (same result as numpy)


@dataclass(frozen=True)
class _Block:
    """The ground actions of one schema: rows start..stop of the structure's arrays."""

    schema: LiftedSchema
    start: int
    stop: int
    columns: Mapping[str, np.ndarray]  # parameter -> object id, one per row
    assumptive: bool

    def select(self, mask: np.ndarray, params: frozenset[str] | None = None
               ) -> tuple[Columns, int]:
        """Columns (all, or those of `params`) of the rows where `mask` (over this block's
        rows) is true."""
        columns = self.columns.items()
        if params is not None:
            columns = [(p, c) for p, c in columns if p in params]
        return {p: np.compress(mask, c) for p, c in columns}, int(np.count_nonzero(mask))


@dataclass(frozen=True)
class GroundStructure:
    """The cached part of grounding: fact table and every statically possible ground action.

    Rows of `pre`, `pre_neg`, `add`, `delete` are ground actions, entries fact ids; padding is
    fact id `len(facts)` in `pre` (read as true) and `len(facts) + 1` elsewhere (never true)."""

    facts: tuple[Atom, ...]
    fact_index: Mapping[Atom, int]
    space: AtomSpace
    blocks: tuple[_Block, ...]
    pre: np.ndarray
    pre_neg: np.ndarray
    add: np.ndarray
    delete: np.ndarray
    clauses: Mapping[int, tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]]
    arg_ids: np.ndarray  # (rows, max arity) object ids of the arguments, padded with -1
    _rows: dict[int, tuple] = field(default_factory=dict, compare=False, repr=False)
    memo: dict[str, object] = field(default_factory=dict, compare=False, repr=False)
    """Arrays other modules derive from the structure (`derived.derived`), kept with it so
    they are freed when the grounding cache drops the structure."""

    @property
    def size(self) -> int:
        return len(self.pre)

    def block_of(self, row: int) -> _Block:
        for block in self.blocks:
            if block.start <= row < block.stop:
                return block
        raise IndexError(row)

    def label(self, row: int) -> str:
        block = self.block_of(row)
        names = self.space.names
        args = (names[int(block.columns[p][row - block.start])] for p in block.schema.params)
        return "(" + " ".join((block.schema.name, *args)) + ")"

    def rows(self, rows: list[int]) -> list[tuple]:
        """Per row: (name, args, pre, pre_neg, add, delete, pre_facts, add_facts, clauses,
        assumptive, signature) of the ground action, built once per structure."""
        known = self._rows
        missing = [r for r in rows if r not in known]
        if missing:
            self._build_rows(missing)
        return [known[r] for r in rows]

    def _build_rows(self, missing: list[int]) -> None:
        n = len(self.facts)
        names = self.space.names
        at = np.array(missing, dtype=np.int64)
        if len(missing) <= _FEW_ROWS:  # a plan's steps: Python lists beat numpy's per-call cost
            pre_rows, add_rows, neg_ids, delete_ids = (
                [sorted({f for f in row if f < n}) for row in a[at].tolist()]
                for a in (self.pre, self.add, self.pre_neg, self.delete))
            pre_masks, add_masks, neg_masks, delete_masks = (
                [bitset(ids) for ids in rows]
                for rows in (pre_rows, add_rows, neg_ids, delete_ids))
            pre_count, add_count = [len(r) for r in pre_rows], [len(r) for r in add_rows]
        else:
            pre, neg, add, delete = (fact_matrix(a[at], n, None)
                                     for a in (self.pre, self.pre_neg, self.add, self.delete))
            pre_masks, neg_masks, add_masks, delete_masks = (
                _row_masks(m, n) for m in (pre, neg, add, delete)
            )
            pre_count = (pre >= 0).sum(axis=1).tolist()
            add_count = (add >= 0).sum(axis=1).tolist()
            pre_rows, add_rows = pre.tolist(), add.tolist()
        arg_rows = self.arg_ids[at].tolist()
        starts = np.array([b.start for b in self.blocks], dtype=np.int64)
        block_rows = (np.searchsorted(starts, at, side="right") - 1).tolist()
        lowered = [x.lower() for x in names]
        clause_rows = self.clauses
        for k, row in enumerate(missing):
            block = self.blocks[block_rows[k]]
            schema = block.schema
            ids = arg_rows[k][: len(schema.params)]
            clauses = ()
            if row in clause_rows:
                clauses = tuple((bitset(pos), bitset(neg)) for pos, neg in clause_rows[row])
            self._rows[row] = (
                schema.name, tuple([names[v] for v in ids]), pre_masks[k], neg_masks[k],
                add_masks[k], delete_masks[k], tuple(pre_rows[k][: pre_count[k]]),
                tuple(add_rows[k][: add_count[k]]), clauses, block.assumptive,
                (schema.name.lower(), *[lowered[v] for v in ids]),
            )
