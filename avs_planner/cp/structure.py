"""The cached part of grounding: every ground action consistent with types and static atoms.

It depends only on the domain, the objects and the static atoms (`GroundingCache` keys it so).
Atoms are integer codes (`encoding.AtomSpace`); a schema's bindings are joined over its static
preconditions as columns of object ids; the ground actions' conditions and effects are rows of
fact-id arrays that the per-call stage (`grounding.ground`) runs its fixpoints over.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from unified_planning.model import FNode, Problem

from avs_planner.cp.bindings import (
    DENSE_CODES,
    CompiledJoin,
    code_set,
    encode_numpy,
    join_numpy,
)
from avs_planner.cp.conditional import Variant, expand_rows, variants
from avs_planner.cp.encoding import AtomSpace, Columns
from avs_planner.cp.formulas import FormulaGrounder
from avs_planner.cp.schema import LiftedSchema
from avs_planner.cp.settled import NO_KEY, NOTHING_SETTLED, Key, SettledAtoms
from avs_planner.cp.task import Atom
from avs_planner.cp.unsupported import UnsupportedError, in_action
from avs_planner.errors import PlanningError

try:  # the compiled join, encoding and numbering; the numpy code computes the same
    from avs_planner.cp import _ground
except ImportError:
    _ground = None

MAX_GROUND_ACTIONS = 2_000_000
MAX_BINDINGS = 20_000_000  # partial bindings of one schema while joining its static atoms
_PAD_TRUE = -1  # padding code of precondition arrays (an always-true fact)
_PAD_NONE = -2  # padding code of the other arrays (a fact nothing reads or makes true)


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


_FEW_ROWS = 64  # up to this many rows are built from Python lists (same result as numpy)


def _row_masks(matrix: np.ndarray, n: int) -> list[int]:
    """Each row's fact ids (>= 0; -1 is padding) as a Python int bitset."""
    words = bit_words(matrix, n)
    data, size = words.tobytes(), words.shape[1] * 8
    return [int.from_bytes(data[i:i + size], "little") for i in range(0, len(data), size)]


def bit_words(matrix: np.ndarray, n_facts: int) -> np.ndarray:
    """Each row's fact ids (>= 0; -1 is padding) as little-endian uint64 words, one spare bit
    so that n_facts = 0 still has a word (the native core's layout)."""
    words = n_facts // 64 + 1
    out = np.zeros((matrix.shape[0], words), dtype="<u8")
    rows, cols = np.nonzero(matrix >= 0)
    facts = matrix[rows, cols]
    np.bitwise_or.at(out, (rows, facts >> 6),
                     np.left_shift(np.uint64(1), (facts & 63).astype(np.uint64)))
    return out


def bitset(ids) -> int:
    """A Python int bitset of fact ids."""
    bits = 0
    for i in ids:
        bits |= 1 << i
    return bits


def _pad(lists: list[list[int]], pad: int) -> np.ndarray:
    width = max((len(x) for x in lists), default=0)
    out = np.full((len(lists), width), pad, dtype=np.int64)
    for i, x in enumerate(lists):
        out[i, : len(x)] = x
    return out


def _read_params(nodes: Sequence[FNode]) -> frozenset[str]:
    """The schema parameters the conditions mention: their CNF depends on nothing else."""
    stack, read = list(nodes), set()
    while stack:
        node = stack.pop()
        if node.is_parameter_exp():
            read.add("?" + node.parameter().name)
        stack.extend(node.args)
    return frozenset(read)


def _complex_rows(
    schema: LiftedSchema, space: AtomSpace, columns: Columns, rows: int,
    formulas: FormulaGrounder,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple]]:
    """Per binding: CNF of the quantified/disjunctive conditions. Unit clauses become extra
    pre/pre_neg codes; longer ones are kept per row. Rows with an empty clause are dropped.
    The CNF is grounded once per distinct binding of the parameters the conditions read
    (e.g. `?r` of createviewcones-in, not `?l`): grounding a quantifier walks the formula
    once per object; copying its result to the rows that share it is one array gather."""
    mentioned = _read_params(schema.complex)
    read = [p for p in schema.params if p in mentioned]
    if read:
        keys = np.stack([columns[p] for p in read], axis=1)
        distinct, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.reshape(-1)
    else:
        distinct, inverse = np.zeros((1, 0), dtype=np.int64), np.zeros(rows, dtype=np.int64)
    names = space.names
    try:
        grounded = [
            _ground_cnf(schema, space, formulas,
                        {p: names[i] for p, i in zip(read, ids, strict=True)})
            for ids in distinct.tolist()
        ]
    except PlanningError as exc:  # name the action, so the reader can place it
        raise in_action(schema.name, exc) from None
    keep = np.array([g[0] for g in grounded], dtype=bool)[inverse]
    pos = _pad([g[1] for g in grounded], _PAD_TRUE)[inverse]
    neg = _pad([g[2] for g in grounded], _PAD_NONE)[inverse]
    longer = [g[3] for g in grounded]
    return keep, pos, neg, [longer[g] for g in inverse.tolist()]


def _ground_cnf(
    schema: LiftedSchema, space: AtomSpace, formulas: FormulaGrounder,
    binding: Mapping[str, str],
) -> tuple[bool, list[int], list[int], tuple]:
    """(satisfiable, unit positive codes, unit negative codes, longer clauses as code pairs)
    of the schema's complex conditions under one binding of the parameters they read."""

    def code(atom: Atom) -> int:
        c = space.encode(atom)
        if c is None:
            raise PlanningError(f"action {schema.name}: cannot ground condition atom {atom}")
        return c

    cnf = [c for node in schema.complex for c in formulas.cnf(node, binding)]
    pos: list[int] = []
    neg: list[int] = []
    longer = []
    for literals in sorted(map(sorted, cnf)):  # each clause's literals sorted once
        if not literals:
            return False, pos, neg, tuple(longer)
        if len(literals) == 1:
            ((atom, positive),) = literals
            (pos if positive else neg).append(code(atom))
        else:
            longer.append((
                tuple(code(a) for a, positive in literals if positive),
                tuple(code(a) for a, positive in literals if not positive),
            ))
    return True, pos, neg, tuple(longer)


def expand_conditional(
    schema: LiftedSchema, space: AtomSpace, columns: Columns, rows: int, keep: np.ndarray,
    arrays: tuple[np.ndarray, ...], clauses: list[tuple] | None,
    statics: tuple[frozenset[Atom], frozenset[str]],
) -> tuple[Columns, int, np.ndarray, tuple[np.ndarray, ...], list[tuple]]:
    """The schema's rows with its conditional effects compiled in (`conditional.py`): a row
    per copy, copies of one ground action next to each other."""
    static, static_names = statics

    def per_binding(binding: dict[str, str]) -> list[Variant]:
        try:
            return variants(schema.conditional, binding, space.encode, static, static_names,
                            space.names_of)
        except PlanningError as exc:  # name the ground action it is about
            args = " ".join(binding[p] for p in schema.params if p in binding)
            raise UnsupportedError(f"action {schema.name}, as ({schema.name} {args}): {exc}",
                                   action=schema.name) from None

    index, found = expand_rows(schema.params, columns, rows, space.names, per_binding)
    pre, neg, add, delete = (a[index] for a in arrays)
    extra = [[v.pre for v in found], [v.neg for v in found], [v.add for v in found],
             [v.delete for v in found]]
    pads = (_PAD_TRUE, _PAD_NONE, _PAD_NONE, _PAD_NONE)
    pre, neg, add, delete = (np.concatenate([a, _pad(e, pad)], axis=1)
                             for a, e, pad in zip((pre, neg, add, delete), extra, pads,
                                                  strict=True))
    old = clauses if clauses is not None else [()] * rows
    merged = [tuple(old[r]) + tuple(v.clauses) for r, v in zip(index.tolist(), found,
                                                             strict=True)]
    expanded = {p: c[index] for p, c in columns.items()}
    return expanded, len(index), keep[index], (pre, neg, add, delete), merged


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


def fact_matrix(ids: np.ndarray, n: int, read: np.ndarray | None) -> np.ndarray:
    """Rows of fact ids sorted and unique, padding (ids >= n) and, if `read` is given,
    facts nothing reads replaced by -1 at the end of the row."""
    big = np.iinfo(np.int64).max
    valid = ids < n
    if read is not None:
        valid[valid] = read[ids[valid]]
    out = np.where(valid, ids, big)
    out.sort(axis=1)
    if out.shape[1] > 1:
        dup = np.zeros(out.shape, dtype=bool)
        dup[:, 1:] = out[:, 1:] == out[:, :-1]
        out[dup] = big
        out.sort(axis=1)
    out[out == big] = -1
    return out
