"""The cached part of grounding: every ground action consistent with types and static atoms.

It depends only on the domain, the objects and the static atoms (`GroundingCache` keys it so).
Atoms are integer codes (`encoding.AtomSpace`); a schema's bindings are joined over its static
preconditions as columns of object ids; the ground actions' conditions and effects are rows of
fact-id arrays that the per-call stage (`grounding.ground`) runs its fixpoints over.

This module builds the structure: `build_structure` joins and encodes each schema's rows, then
`_assemble` stacks them and numbers the atom codes they use as fact ids. Every choice between
the compiled `_ground` and the numpy code is made here, so one switch (`_ground = None`) runs
the whole build on numpy. What it builds and how rows are read is `ground_structure.py`;
complex conditions and conditional effects are compiled by `condition_rows.py`; the row
layouts and bitsets are `fact_rows.py`. Their public names are re-exported here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.bindings import (
    DENSE_CODES,
    CompiledJoin,
    code_set,
    encode_numpy,
    join_numpy,
)
from avs_planner.cp.condition_rows import _complex_rows, expand_conditional
from avs_planner.cp.encoding import AtomSpace
from avs_planner.cp.fact_rows import _PAD_NONE, _PAD_TRUE, bit_words, bitset, fact_matrix
from avs_planner.cp.formulas import FormulaGrounder
from avs_planner.cp.ground_structure import GroundStructure, _Block
from avs_planner.cp.schema import LiftedSchema
from avs_planner.cp.settled import NO_KEY, NOTHING_SETTLED, Key, SettledAtoms
from avs_planner.cp.task import Atom
from avs_planner.errors import PlanningError

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import Problem

try:  # the compiled join, encoding and numbering; the numpy code computes the same
    from avs_planner.cp import _ground
except ImportError:
    _ground = None

__all__ = [
    "MAX_BINDINGS",
    "MAX_GROUND_ACTIONS",
    "GroundStructure",
    "bit_words",
    "bitset",
    "build_structure",
    "expand_conditional",
    "fact_matrix",
]

MAX_GROUND_ACTIONS = 2_000_000
MAX_BINDINGS = 20_000_000  # partial bindings of one schema while joining its static atoms


def build_structure(
    problem: Problem, schemas: Sequence[LiftedSchema], static: frozenset[Atom],
    assumptive: Mapping[str, bool], static_names: frozenset[str] | None = None,
    settled: SettledAtoms = NOTHING_SETTLED, settled_key: Key = NO_KEY,
) -> GroundStructure:
    """Ground every action over the objects, filtered by types, static atoms and what the
    state settles for good (`settled.py`: `settled_key` is `settled.key` of the state)."""
    space = AtomSpace(problem)
    static_codes = space.encode_all(static)
    if settled is not NOTHING_SETTLED:
        static_codes = np.concatenate([static_codes, settled.codes(space, settled_key)])
    compiled = CompiledJoin(space, static_codes) if _ground is not None else None
    is_static = code_set(static_codes, space.size) if compiled is None else None
    if static_names is None:
        static_names = frozenset(f.name for f in problem.get_static_fluents())
    formulas = FormulaGrounder(static, static_names, space.names_of)
    parts = []  # (schema, columns, rows, pre, neg, add, delete, {row: its longer clauses})
    total = 0
    for schema in schemas:
        if schema.never:
            continue
        if compiled is not None:
            matrix, rows = compiled.bindings(settled.joined(schema, settled_key), MAX_BINDINGS,
                                             MAX_GROUND_ACTIONS)
            index = {p: i for i, p in enumerate(schema.params)}
            by_param = np.ascontiguousarray(matrix.T)
            columns = {p: by_param[i] for p, i in index.items()}

            def code(templates, index=index, matrix=matrix):
                return compiled.codes(templates, index, matrix)
        else:
            columns, rows = join_numpy(settled.joined(schema, settled_key), space, is_static,
                                       MAX_BINDINGS)

            def code(templates, columns=columns, rows=rows):
                return encode_numpy(templates, space, columns, rows)
        if not rows:
            continue
        pre = code(schema.pre_pos)
        neg = code(schema.pre_neg)
        clauses: list[tuple] | None = None  # per row, only for schemas with complex conditions
        if schema.complex:
            keep, more_pos, more_neg, clauses = _complex_rows(
                schema, space, columns, rows, formulas
            )
            pre = np.concatenate([pre, more_pos], axis=1)
            neg = np.concatenate([neg, more_neg], axis=1)
        else:
            keep = np.ones(rows, dtype=bool)
        add = code(schema.add)
        delete = code(schema.delete)
        if schema.conditional:
            columns, rows, keep, (pre, neg, add, delete), clauses = expand_conditional(
                schema, space, columns, rows, keep, (pre, neg, add, delete), clauses,
                (static, static_names))
        if pre.shape[1] and neg.shape[1]:  # a condition and its negation: never applicable
            keep &= ~(pre[:, :, None] == neg[:, None, :]).any(axis=(1, 2))
        if add.shape[1] and delete.shape[1]:  # add wins over delete (PDDL: deletes first)
            delete[(delete[:, :, None] == add[:, None, :]).any(axis=2)] = _PAD_NONE
        if not keep.all():
            columns = {p: c[keep] for p, c in columns.items()}
            pre, neg, add, delete = pre[keep], neg[keep], add[keep], delete[keep]
            if clauses is not None:
                clauses = [c for c, k in zip(clauses, keep.tolist(), strict=True) if k]
            rows = int(keep.sum())
        total += rows
        if total > MAX_GROUND_ACTIONS:
            raise PlanningError(f"grounding exceeds {MAX_GROUND_ACTIONS} actions")
        if rows:
            sparse = {i: c for i, c in enumerate(clauses) if c} if clauses else {}
            parts.append((schema, columns, rows, pre, neg, add, delete, sparse))
    return _assemble(space, parts, assumptive)


def _assemble(space: AtomSpace, parts: list, assumptive: Mapping[str, bool]) -> GroundStructure:
    """Concatenate the schemas' rows and renumber the atom codes they use as fact ids."""
    starts = np.cumsum([0] + [part[2] for part in parts]).tolist()
    row_clauses = {start + i: c for part, start in zip(parts, starts, strict=False)
                   for i, c in part[7].items()}
    distinct_clauses = list(dict.fromkeys(row_clauses.values()))
    clause_codes = np.array([c for row in distinct_clauses for clause in row for side in clause
                             for c in side], dtype=np.int64)
    arrays = [[part[3 + k] for part in parts] for k in range(4)]
    entries = sum(a.size for kind in arrays for a in kind) + clause_codes.size
    if _ground is not None and space.size <= max(DENSE_CODES, 2 * entries):
        stacked, codes = _stack_compiled(space.size, arrays, clause_codes, starts[-1])
    else:
        stacked, codes = _stack(space.size, arrays, clause_codes, starts)
    n = len(codes)
    facts = tuple(space.decode_many(codes))
    index_of = {c: i for i, c in enumerate(codes.tolist())}
    renumbered = {
        row: tuple((tuple(index_of[c] for c in pos), tuple(index_of[c] for c in neg))
                   for pos, neg in row)
        for row in distinct_clauses
    }
    clauses = {i: renumbered[row] for i, row in row_clauses.items()}
    blocks, start = [], 0
    arity = max((len(part[0].params) for part in parts), default=0)
    arg_ids = np.full((starts[-1], arity), -1, dtype=np.int64)
    for schema, columns, rows, *_ in parts:
        blocks.append(_Block(schema, start, start + rows, columns, assumptive[schema.name]))
        for j, param in enumerate(schema.params):
            arg_ids[start:start + rows, j] = columns[param]
        start += rows
    return GroundStructure(
        facts=facts, fact_index=dict(zip(facts, range(n), strict=True)),
        space=space, blocks=tuple(blocks), pre=stacked["pre"],
        pre_neg=stacked["neg"], add=stacked["add"], delete=stacked["delete"], clauses=clauses,
        arg_ids=arg_ids,
    )


_KINDS = ("pre", "neg", "add", "delete")


def _stack(space_size: int, arrays: list[list[np.ndarray]], extra: np.ndarray,
           starts: list[int]) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The four stacked matrices of fact ids (each padded with its pad's fact id) and the
    atom codes used, sorted (fact id = position)."""
    codes, renumber = _fact_numbering(space_size, [a for kind in arrays for a in kind], extra)
    n = len(codes)
    # each schema's codes renumbered straight into the stacked arrays, whose padding is
    # already the pads' fact ids (one pass over the big arrays instead of two)
    stacked = {}
    for key, pad, kind in zip(_KINDS, (n, n + 1, n + 1, n + 1), arrays, strict=True):
        width = max((a.shape[1] for a in kind), default=0)
        out = stacked[key] = np.empty((starts[-1], width), dtype=np.int64)
        for array, start in zip(kind, starts, strict=False):
            rows = out[start:start + len(array)]
            if array.shape[1] == width:  # contiguous: written in place
                renumber(array, rows)
            else:
                rows[:, : array.shape[1]] = renumber(array)
                rows[:, array.shape[1]:] = pad
    return stacked, codes


def _stack_compiled(space_size: int, arrays: list[list[np.ndarray]], extra: np.ndarray,
                    total: int) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """`_stack` in C (`_ground.number` and `_ground.renumber`): the same arrays."""
    flat = [np.ascontiguousarray(a, dtype=np.int64) for kind in arrays for a in kind]
    codes, table = _ground.number(space_size, [*flat, np.ascontiguousarray(extra)])
    codes = np.frombuffer(codes, dtype=np.int64)
    n = len(codes)
    stacked, k = {}, 0
    for key, pad, kind in zip(_KINDS, (n, n + 1, n + 1, n + 1), arrays, strict=True):
        width = max((a.shape[1] for a in kind), default=0)
        out = stacked[key] = np.empty((total, width), dtype=np.int64)
        _ground.renumber(table, flat[k:k + len(kind)],
                         np.array([a.shape for a in kind], dtype=np.int64), out, width, pad)
        k += len(kind)
    return stacked, codes


def _fact_numbering(
    space_size: int, arrays: list[np.ndarray], extra: np.ndarray
) -> tuple[np.ndarray, Callable[..., np.ndarray]]:
    """The atom codes used (sorted) and `renumber(codes, out=None)`, which gives the fact ids
    of a code array (written into `out`, contiguous and of the same shape, if given),
    padding codes `_PAD_TRUE` -> n and `_PAD_NONE` -> n + 1. When the code space is small
    next to the arrays (the usual case), a dense table replaces sort-based unique and
    searchsorted, several times faster; huge code spaces (up to `MAX_CODE`) take the sorted
    path."""
    entries = sum(a.size for a in arrays) + extra.size
    if space_size <= max(DENSE_CODES, 2 * entries):
        used = np.zeros(space_size + 2, dtype=bool)  # the pads index the last two slots
        for array in (*arrays, extra):
            used[array.reshape(-1)] = True
        used[-2:] = False
        codes = np.flatnonzero(used)
        n = len(codes)
        table = np.empty(space_size + 2, dtype=np.int64)
        table[codes] = np.arange(n)
        table[_PAD_TRUE], table[_PAD_NONE] = n, n + 1

        def lookup(array: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
            # "wrap" reads the pads (-1, -2) from the table's end, as indexing would (codes
            # are in [-2, space_size)), and is faster than indexing or the default mode
            return np.take(table, array, out=out, mode="wrap")

        return codes, lookup
    codes = np.unique(np.concatenate([a[a >= 0] for a in arrays] + [extra]))
    n = len(codes)

    def renumber(array: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        ids = np.searchsorted(codes, array)
        ids[array == _PAD_TRUE] = n
        ids[array == _PAD_NONE] = n + 1
        if out is None:
            return ids
        out[...] = ids
        return out

    return codes, renumber
