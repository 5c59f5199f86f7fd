"""Grounding a probabilistic task to bitsets, with a cache reused across replans.

Two stages. The *structure* (every ground action consistent with types and static atoms, and
the fact table) depends only on the domain, the objects and the static atoms, so it is cached
under that key. The *instance* (initial bitset, relaxed-reachable actions, costs and success
probabilities evaluated from numeric values) is rebuilt for every call.

Both stages work on arrays: atoms are integer codes (`encoding.AtomSpace`), a schema's
bindings are columns of object ids built by a join over its static preconditions, and the
reachability and relevance fixpoints run over (ground action x condition) arrays of fact ids.
Only the ground actions that survive become `GroundAction` objects.
"""

from __future__ import annotations

import gc
from collections import OrderedDict
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from unified_planning.model import FNode, Problem

from avs_planner.cp.encoding import AtomSpace, Columns
from avs_planner.cp.formulas import FormulaGrounder
from avs_planner.cp.schema import AtomTemplate, LiftedSchema, compile_schemas
from avs_planner.cp.task import Atom, GroundAction, GroundTask, TaskArrays, WorldState
from avs_planner.errors import PlanningError
from avs_planner.pddl.model import ProbabilisticProblem

MAX_GROUND_ACTIONS = 2_000_000
MAX_BINDINGS = 20_000_000  # partial bindings of one schema while joining its static atoms
_PAD_TRUE = -1  # padding code of precondition arrays (an always-true fact)
_PAD_NONE = -2  # padding code of the other arrays (a fact nothing reads or makes true)


def world_state(problem: Problem) -> WorldState:
    """The problem's initial state as atoms and numeric values (explicit :init entries)."""
    atoms: set[Atom] = set()
    values: dict[Atom, float] = {}
    for fluent_exp, value in problem.explicit_initial_values.items():
        key = (fluent_exp.fluent().name, *(str(a.object().name) for a in fluent_exp.args))
        if value.is_bool_constant():
            if value.bool_constant_value():
                atoms.add(key)
        elif value.is_int_constant() or value.is_real_constant():
            values[key] = float(value.constant_value())
    return WorldState(frozenset(atoms), values)


@dataclass(frozen=True)
class _Block:
    """The ground actions of one schema: rows start..stop of the structure's arrays."""

    schema: LiftedSchema
    start: int
    stop: int
    columns: Mapping[str, np.ndarray]  # parameter -> object id, one per row
    assumptive: bool

    def select(self, mask: np.ndarray) -> tuple[Columns, int]:
        """Columns of the rows where `mask` (over this block's rows) is true."""
        return {p: c[mask] for p, c in self.columns.items()}, int(mask.sum())


@dataclass(frozen=True)
class GroundStructure:
    """The cached part of grounding: fact table and every statically possible ground action.

    Rows of `pre`, `pre_neg`, `add`, `delete` are ground actions, entries fact ids; padding is
    fact id `len(facts)` in `pre` (read as true) and `len(facts) + 1` elsewhere (never true)."""

    facts: tuple[Atom, ...]
    fact_index: Mapping[Atom, int]
    static_atoms: frozenset[Atom]
    space: AtomSpace
    blocks: tuple[_Block, ...]
    pre: np.ndarray
    pre_neg: np.ndarray
    add: np.ndarray
    delete: np.ndarray
    clauses: Mapping[int, tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]]
    arg_ids: np.ndarray  # (rows, max arity) object ids of the arguments, padded with -1
    _rows: dict[int, tuple] = field(default_factory=dict, compare=False, repr=False)

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
        pre, neg, add, delete = (_fact_matrix(a[at], n, None)
                                 for a in (self.pre, self.pre_neg, self.add, self.delete))
        pre_masks, neg_masks, add_masks, delete_masks = (
            _row_masks(m, n) for m in (pre, neg, add, delete)
        )
        pre_count, add_count = (pre >= 0).sum(axis=1).tolist(), (add >= 0).sum(axis=1).tolist()
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
                clauses = tuple((_mask(pos), _mask(neg)) for pos, neg in clause_rows[row])
            self._rows[row] = (
                schema.name, tuple([names[v] for v in ids]), pre_masks[k], neg_masks[k],
                add_masks[k], delete_masks[k], tuple(pre_rows[k][: pre_count[k]]),
                tuple(add_rows[k][: add_count[k]]), clauses, block.assumptive,
                (schema.name.lower(), *[lowered[v] for v in ids]),
            )


def _row_masks(matrix: np.ndarray, n: int) -> list[int]:
    """Each row's fact ids (>= 0; -1 is padding) as a Python int bitset."""
    words = n // 64 + 1
    out = np.zeros((matrix.shape[0], words), dtype=np.uint64)
    rows, cols = np.nonzero(matrix >= 0)
    facts = matrix[rows, cols]
    np.bitwise_or.at(out, (rows, facts // 64),
                     np.left_shift(np.uint64(1), (facts % 64).astype(np.uint64)))
    data, size = out.tobytes(), 8 * words
    return [int.from_bytes(data[i:i + size], "little") for i in range(0, len(data), size)]


def _mask(ids) -> int:
    mask = 0
    for i in ids:
        mask |= 1 << i
    return mask


def _member(codes: np.ndarray, sorted_codes: np.ndarray) -> np.ndarray:
    if len(sorted_codes) == 0:
        return np.zeros(len(codes), dtype=bool)
    at = np.minimum(np.searchsorted(sorted_codes, codes), len(sorted_codes) - 1)
    return sorted_codes[at] == codes


def _term_params(terms: Sequence[str]) -> frozenset[str]:
    return frozenset(t for t in terms if t[0] == "?")


def _bindings(
    schema: LiftedSchema, space: AtomSpace, static_codes: np.ndarray
) -> tuple[dict[str, np.ndarray], int]:
    """Every parameter binding consistent with types, static atoms and (in)equalities, as
    columns of object ids in lexicographic order of the schema's parameters. A join: one
    parameter at a time (the one closing most constraints first), filtering as soon as a
    constraint's parameters are all bound."""
    params = schema.params
    domain = {p: space.objects_of(t) for p, t in zip(params, schema.param_types, strict=True)}
    pending = (
        [("in", t, _term_params(t[1:])) for t in schema.static_pos]
        + [("out", t, _term_params(t[1:])) for t in schema.static_neg]
        + [("eq", pair, _term_params(pair)) for pair in schema.equal]
        + [("ne", pair, _term_params(pair)) for pair in schema.not_equal]
    )
    columns: dict[str, np.ndarray] = {}
    rows = 1

    def value(term: str, rows: int) -> np.ndarray:
        if term[0] == "?":
            return columns[term]
        return np.full(rows, space.object_id[term], dtype=np.int64)

    def apply(ready: list) -> None:
        nonlocal columns, rows
        mask = np.ones(rows, dtype=bool)
        for kind, item, _ in ready:
            if kind in ("in", "out"):
                hit = _member(space.encode_rows(item, columns, rows), static_codes)
                mask &= hit if kind == "in" else ~hit
            else:
                same = value(item[0], rows) == value(item[1], rows)
                mask &= same if kind == "eq" else ~same
        if not mask.all():
            columns = {p: c[mask] for p, c in columns.items()}
            rows = int(mask.sum())

    bound: set[str] = set()
    apply([c for c in pending if not c[2]])
    pending = [c for c in pending if c[2]]
    remaining = list(params)
    while remaining and rows:
        param = min(remaining, key=lambda p, pending=pending: (
            -sum(1 for c in pending if c[2] <= bound | {p}), len(domain[p]), params.index(p)
        ))
        remaining.remove(param)
        objects = domain[param]
        if rows * len(objects) > MAX_BINDINGS:
            raise PlanningError(
                f"action {schema.name}: more than {MAX_BINDINGS} partial bindings to ground"
            )
        columns = {p: np.repeat(c, len(objects)) for p, c in columns.items()}
        columns[param] = np.tile(objects, rows)
        rows *= len(objects)
        bound.add(param)
        apply([c for c in pending if c[2] <= bound])
        pending = [c for c in pending if not c[2] <= bound]
    if not rows or remaining:
        return {p: np.zeros(0, dtype=np.int64) for p in params}, 0
    if params:
        order = np.lexsort([columns[p] for p in reversed(params)])
        columns = {p: columns[p][order] for p in params}
    return columns, rows


def _codes(templates: Sequence[AtomTemplate], space: AtomSpace, columns: Columns,
           rows: int) -> np.ndarray:
    if not templates:
        return np.empty((rows, 0), dtype=np.int64)
    return np.stack([space.encode_rows(t, columns, rows) for t in templates], axis=1)


def _pad(lists: list[list[int]], pad: int) -> np.ndarray:
    width = max((len(x) for x in lists), default=0)
    out = np.full((len(lists), width), pad, dtype=np.int64)
    for i, x in enumerate(lists):
        out[i, : len(x)] = x
    return out


def _complex_rows(schema, space, columns, rows, formulas):
    """Per binding: CNF of the quantified/disjunctive conditions. Unit clauses become extra
    pre/pre_neg codes; longer ones are kept per row. Rows with an empty clause are dropped."""
    keep = np.ones(rows, dtype=bool)
    extra_pos: list[list[int]] = []
    extra_neg: list[list[int]] = []
    clauses: list[tuple] = []
    names = space.names

    def code(atom: Atom) -> int:
        c = space.encode(atom)
        if c is None:
            raise PlanningError(f"action {schema.name}: cannot ground condition atom {atom}")
        return c

    for i in range(rows):
        binding = {p: names[int(columns[p][i])] for p in schema.params}
        cnf = [c for node in schema.complex for c in formulas.cnf(node, binding)]
        pos: list[int] = []
        neg: list[int] = []
        longer = []
        for clause in sorted(cnf, key=lambda c: sorted(c)):
            if not clause:
                keep[i] = False
                break
            if len(clause) == 1:
                ((atom, positive),) = clause
                (pos if positive else neg).append(code(atom))
            else:
                longer.append((
                    tuple(code(a) for a, positive in sorted(clause) if positive),
                    tuple(code(a) for a, positive in sorted(clause) if not positive),
                ))
        extra_pos.append(pos)
        extra_neg.append(neg)
        clauses.append(tuple(longer))
    return keep, _pad(extra_pos, _PAD_TRUE), _pad(extra_neg, _PAD_NONE), clauses


def _widen(array: np.ndarray, width: int, pad: int) -> np.ndarray:
    if array.shape[1] == width:
        return array
    out = np.full((array.shape[0], width), pad, dtype=np.int64)
    out[:, : array.shape[1]] = array
    return out


def build_structure(
    problem: Problem, schemas: Sequence[LiftedSchema], static: frozenset[Atom],
    assumptive: Mapping[str, bool], static_names: frozenset[str] | None = None,
) -> GroundStructure:
    """Ground every action over the objects, filtered by types and static atoms."""
    space = AtomSpace(problem)
    static_codes = np.unique(np.array(
        [c for c in (space.encode(a) for a in static) if c is not None], dtype=np.int64
    ))
    if static_names is None:
        static_names = frozenset(f.name for f in problem.get_static_fluents())
    formulas = FormulaGrounder(static, static_names, space.names_of)
    parts = []  # (schema, columns, rows, pre, neg, add, delete, clauses per row)
    total = 0
    for schema in schemas:
        if schema.never:
            continue
        columns, rows = _bindings(schema, space, static_codes)
        if not rows:
            continue
        pre = _codes(schema.pre_pos, space, columns, rows)
        neg = _codes(schema.pre_neg, space, columns, rows)
        clauses: list[tuple] = [()] * rows
        if schema.complex:
            keep, more_pos, more_neg, clauses = _complex_rows(
                schema, space, columns, rows, formulas
            )
            pre = np.concatenate([pre, more_pos], axis=1)
            neg = np.concatenate([neg, more_neg], axis=1)
        else:
            keep = np.ones(rows, dtype=bool)
        for i in range(pre.shape[1]):  # a condition and its negation: never applicable
            for j in range(neg.shape[1]):
                keep &= pre[:, i] != neg[:, j]
        add = _codes(schema.add, space, columns, rows)
        delete = _codes(schema.delete, space, columns, rows)
        for j in range(delete.shape[1]):  # add wins over delete (PDDL: deletes first)
            for i in range(add.shape[1]):
                delete[:, j] = np.where(delete[:, j] == add[:, i], _PAD_NONE, delete[:, j])
        if not keep.all():
            columns = {p: c[keep] for p, c in columns.items()}
            pre, neg, add, delete = pre[keep], neg[keep], add[keep], delete[keep]
            clauses = [c for c, k in zip(clauses, keep.tolist(), strict=True) if k]
            rows = int(keep.sum())
        total += rows
        if total > MAX_GROUND_ACTIONS:
            raise PlanningError(f"grounding exceeds {MAX_GROUND_ACTIONS} actions")
        if rows:
            parts.append((schema, columns, rows, pre, neg, add, delete, clauses))
    return _assemble(problem, space, static, parts, assumptive)


def _assemble(problem, space, static, parts, assumptive) -> GroundStructure:
    """Concatenate the schemas' rows and renumber the atom codes they use as fact ids."""
    arrays = {k: [] for k in ("pre", "neg", "add", "delete")}
    clause_codes: list = []
    for _, _, _, pre, neg, add, delete, clauses in parts:
        for key, array in zip(arrays, (pre, neg, add, delete), strict=True):
            arrays[key].append(array)
        clause_codes.extend(c for row in clauses for clause in row for side in clause
                            for c in side)
    used = [a[a >= 0] for key in arrays for a in arrays[key]]
    codes = np.unique(np.concatenate(used + [np.array(clause_codes, dtype=np.int64)]))
    n = len(codes)
    facts = tuple(space.decode_many(codes))

    def renumber(array: np.ndarray, pad: int) -> np.ndarray:
        out = np.searchsorted(codes, array)
        out[array == _PAD_TRUE] = n
        out[array == _PAD_NONE] = n + 1
        return out

    stacked = {}
    for key, pad in (("pre", _PAD_TRUE), ("neg", _PAD_NONE), ("add", _PAD_NONE),
                     ("delete", _PAD_NONE)):
        width = max((a.shape[1] for a in arrays[key]), default=0)
        joined = (np.concatenate([_widen(a, width, pad) for a in arrays[key]])
                  if arrays[key] else np.empty((0, 0), dtype=np.int64))
        stacked[key] = renumber(joined, pad)
    blocks, clauses, start = [], {}, 0
    index_of = {c: i for i, c in enumerate(codes.tolist())}
    arity = max((len(part[0].params) for part in parts), default=0)
    arg_ids = np.full((sum(part[2] for part in parts), arity), -1, dtype=np.int64)
    for schema, columns, rows, *_, row_clauses in parts:
        blocks.append(_Block(schema, start, start + rows, columns, assumptive[schema.name]))
        for j, param in enumerate(schema.params):
            arg_ids[start:start + rows, j] = columns[param]
        for i, row in enumerate(row_clauses):
            if row:
                clauses[start + i] = tuple(
                    (tuple(index_of[c] for c in pos), tuple(index_of[c] for c in neg))
                    for pos, neg in row
                )
        start += rows
    return GroundStructure(
        facts=facts, fact_index={a: i for i, a in enumerate(facts)},
        static_atoms=static, space=space, blocks=tuple(blocks), pre=stacked["pre"],
        pre_neg=stacked["neg"], add=stacked["add"], delete=stacked["delete"], clauses=clauses,
        arg_ids=arg_ids,
    )


def _goal(problem: Problem, structure: GroundStructure, true_atoms: frozenset[Atom]
          ) -> tuple[int, int, bool]:
    """Goal bitsets (positive, negative) and whether a goal atom no action touches (so its
    truth is the initial state's) makes it impossible."""
    pos = neg = 0
    impossible = False
    index = structure.fact_index
    for goal in problem.goals:
        for cond in _flatten(goal):
            negated = cond.is_not()
            inner = cond.arg(0) if negated else cond
            if not inner.is_fluent_exp():
                raise PlanningError(f"unsupported goal condition {cond}")
            atom = (inner.fluent().name, *(a.object().name for a in inner.args))
            i = index.get(atom)
            if i is None:
                # never mentioned by any action: its truth is fixed by the initial state
                impossible |= (atom in true_atoms) == negated
                continue
            if negated:
                neg |= 1 << i
            else:
                pos |= 1 << i
    return pos, neg, impossible or bool(pos & neg)


def _flatten(node: FNode) -> list[FNode]:
    if node.is_and():
        return [c for a in node.args for c in _flatten(a)]
    return [node]


def _ids(mask: int) -> list[int]:
    out, i = [], 0
    while mask:
        if mask & 1:
            out.append(i)
        mask >>= 1
        i += 1
    return out


def _reachable(st: GroundStructure, init: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    """Relaxed reachability (negative preconditions and clauses ignored) over the rows in
    `allowed`: the rows that may ever apply. `init` is a boolean array over fact ids + pads."""
    reached = init.copy()
    active = np.zeros(st.size, dtype=bool)
    waiting = np.flatnonzero(allowed)
    none = len(st.facts) + 1
    while len(waiting):
        ok = reached[st.pre[waiting]].all(axis=1)
        if not ok.any():
            break
        new = waiting[ok]
        waiting = waiting[~ok]
        active[new] = True
        before = int(reached.sum())
        reached[st.add[new]] = True
        reached[none] = False
        if int(reached.sum()) == before:
            break
    return active


def _relevant(st: GroundStructure, allowed: np.ndarray, goal: int, goal_neg: int) -> np.ndarray:
    """Backward relevance: keep actions that add a fact needed true or delete one needed
    false, where needs grow by the kept actions' conditions. Dropping the rest loses no plan
    (they can be cut from any plan, which only lowers its cost and raises its probability)."""
    n = len(st.facts)
    need_true = np.zeros(n + 2, dtype=bool)
    need_false = np.zeros(n + 2, dtype=bool)
    need_true[_ids(goal)] = True
    need_false[_ids(goal_neg)] = True
    kept = np.zeros(st.size, dtype=bool)
    waiting = np.flatnonzero(allowed)
    while len(waiting):
        hit = need_true[st.add[waiting]].any(axis=1) | need_false[st.delete[waiting]].any(axis=1)
        if not hit.any():
            break
        new = waiting[hit]
        waiting = waiting[~hit]
        kept[new] = True
        need_true[st.pre[new]] = True
        need_false[st.pre_neg[new]] = True
        for row in new.tolist():
            for pos, neg in st.clauses.get(row, ()):
                need_true[list(pos)] = True
                need_false[list(neg)] = True
        need_true[n:] = False
        need_false[n:] = False
    return kept


def _evaluate(st: GroundStructure, rows: np.ndarray, values: Mapping[Atom, float],
              what: str) -> np.ndarray:
    """Success probability (`what` = "prob") or cost of the rows in the boolean mask."""
    out = np.zeros(st.size)
    for block in st.blocks:
        sel = rows[block.start:block.stop]
        if not sel.any():
            continue
        columns, count = block.select(sel)
        expr = block.schema.prob_vec if what == "prob" else block.schema.cost_vec
        out[block.start:block.stop][sel] = expr(st.space, columns, count, values)
    return out


def _check(st: GroundStructure, rows: np.ndarray, values: np.ndarray, what: str) -> None:
    if what == "prob":
        bad = rows & ~((values >= 0.0) & (values <= 1.0))
    else:
        bad = rows & ~((values >= 0.0) & np.isfinite(values))
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        if what == "prob":
            raise PlanningError(
                f"success probability of {st.label(row)} is {values[row]}, not in [0, 1]"
            )
        raise PlanningError(f"cost of {st.label(row)} is {values[row]} (must be >= 0)")


def _fact_matrix(ids: np.ndarray, n: int, read: np.ndarray | None) -> np.ndarray:
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


def _bits(flags: np.ndarray) -> int:
    return int.from_bytes(np.packbits(flags, bitorder="little").tobytes(), "little")


class _HashOnce:
    """A cache key whose (costly: UP actions hash structurally) hash is computed once."""

    __slots__ = ("value", "_hash")

    def __init__(self, value: tuple):
        self.value = value
        self._hash = hash(value)

    def __hash__(self) -> int:
        return self._hash

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _HashOnce) and (
            other is self or (other._hash == self._hash and other.value == self.value)
        )


class GroundingCache:
    """Keeps compiled schemas and ground structures for the last few (domain, objects, statics)."""

    def __init__(self, size: int = 16):
        self.size = size
        self._schemas: OrderedDict[tuple, tuple[LiftedSchema, ...]] = OrderedDict()
        self._structures: OrderedDict[tuple, GroundStructure] = OrderedDict()
        self._problem_keys: OrderedDict[int, tuple] = OrderedDict()
        self.hits = 0
        self.misses = 0

    def _remember(self, store: OrderedDict, key, make):
        if key in store:
            store.move_to_end(key)
            self.hits += 1
            return store[key]
        self.misses += 1
        value = store[key] = make()
        if len(store) > self.size:
            store.popitem(last=False)
        return value

    def schemas(self, pproblem: ProbabilisticProblem) -> tuple[LiftedSchema, ...]:
        key, names = self._keys(pproblem)
        return self._remember(self._schemas, key, lambda: compile_schemas(pproblem, names))

    def _keys(self, pproblem: ProbabilisticProblem) -> tuple[tuple, frozenset[str]]:
        """The schema key and static fluent names of a problem, computed once per problem
        object (hashing UP actions and finding static fluents walks the whole domain). A
        problem must not be changed after it was grounded; build a new one instead."""
        known = self._problem_keys.get(id(pproblem))
        if known is not None and known[0] is pproblem:
            return known[1], known[2]
        problem = pproblem.problem
        static_names = frozenset(f.name for f in problem.get_static_fluents())
        key = _HashOnce((
            tuple(problem.actions),
            tuple(sorted((k, str(v)) for k, v in pproblem.success.items())),
            tuple(str(m) for m in problem.quality_metrics),
            static_names,
        ))
        objects = _HashOnce(tuple((o.name, str(o.type)) for o in problem.all_objects))
        self._problem_keys[id(pproblem)] = (pproblem, key, static_names, objects)
        if len(self._problem_keys) > self.size:
            self._problem_keys.popitem(last=False)
        return key, static_names

    def structure(self, pproblem: ProbabilisticProblem, state: WorldState) -> GroundStructure:
        problem = pproblem.problem
        schema_key, static_names = self._keys(pproblem)
        schemas = self.schemas(pproblem)
        objects = self._problem_keys[id(pproblem)][3]
        static = frozenset(a for a in state.true_atoms if a[0] in static_names)
        key = (schema_key, objects, static)
        assumptive = {s.name: pproblem.is_assumptive(s.name) for s in schemas}
        return self._remember(
            self._structures, key,
            lambda: build_structure(problem, schemas, static, assumptive, static_names),
        )


DEFAULT_CACHE = GroundingCache()


@contextmanager
def gc_paused() -> Iterator[None]:
    """Planning allocates many small, acyclic objects; the cyclic collector's passes over a
    large heap then cost more than the grounding (measured 0.31 s vs 0.11 s for a 12-place
    AVS problem). It is paused for a planning call and restored after (as `timeit` does)."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def ground(
    pproblem: ProbabilisticProblem,
    state: WorldState | None = None,
    cache: GroundingCache | None = None,
) -> GroundTask:
    """Ground the task from `state` (default: the problem's :init) into a `GroundTask`."""
    with gc_paused():
        return _ground(pproblem, state, cache)


def _ground(
    pproblem: ProbabilisticProblem, state: WorldState | None, cache: GroundingCache | None
) -> GroundTask:
    cache = DEFAULT_CACHE if cache is None else cache
    state = world_state(pproblem.problem) if state is None else state
    structure = cache.structure(pproblem, state)
    st = structure
    n = len(st.facts)
    init_ids = [i for i in map(st.fact_index.get, state.true_atoms) if i is not None]
    init = _mask(init_ids)
    goal, goal_neg, impossible = _goal(pproblem.problem, st, state.true_atoms)
    reached = np.zeros(n + 2, dtype=bool)
    reached[init_ids] = True
    reached[n] = True  # the padding of preconditions
    # drop actions that can never succeed (p = 0), then what only they made reachable;
    # only reachable actions are evaluated (others may read values :init does not give)
    reachable = _reachable(st, reached, np.ones(st.size, dtype=bool))
    probability = _evaluate(st, reachable, state.values, "prob")
    _check(st, reachable, probability, "prob")
    possible = reachable & (probability > 0.0)
    kept = _relevant(st, _reachable(st, reached, possible), goal, goal_neg)
    cost = _evaluate(st, kept, state.values, "cost")
    _check(st, kept, cost, "cost")
    # effects on facts nothing reads are dropped (e.g. `visited` of ordinary places), so
    # states differing only there merge
    read = np.zeros(n + 2, dtype=bool)
    read[_ids(goal | goal_neg)] = True
    read[st.pre[kept]] = True
    read[st.pre_neg[kept]] = True
    rows = np.flatnonzero(kept).tolist()
    for row in rows:
        for pos, neg in st.clauses.get(row, ()):
            read[list(pos)] = True
            read[list(neg)] = True
    read_mask = _bits(read[:n])
    actions = []
    by_signature = {}
    costs, probabilities = cost.tolist(), probability.tolist()
    unread = ~read_mask
    for index, (row, info) in enumerate(zip(rows, st.rows(rows), strict=True)):
        (name, args, pre, neg, add, delete, pre_facts, add_facts, clauses, assume,
         signature) = info
        if add & unread:
            add &= read_mask
            add_facts = tuple(f for f in add_facts if read_mask >> f & 1)
        action = GroundAction(
            index, name, args, pre, neg, add, delete & read_mask, costs[row],
            probabilities[row], assume, pre_facts, add_facts, clauses,
        )
        actions.append(action)
        by_signature[signature] = action
    kept_rows = np.array(rows, dtype=np.int64)
    arrays = TaskArrays(
        pre=_fact_matrix(st.pre[kept_rows], n, None),
        pre_neg=_fact_matrix(st.pre_neg[kept_rows], n, None),
        add=_fact_matrix(st.add[kept_rows], n, read),
        delete=_fact_matrix(st.delete[kept_rows], n, read),
        cost=cost[kept_rows], probability=probability[kept_rows],
    )
    return GroundTask(
        facts=structure.facts, fact_index=structure.fact_index, actions=tuple(actions),
        init=init, goal=goal, goal_neg=goal_neg, goal_impossible=impossible,
        by_signature=by_signature, arrays=arrays,
    )
