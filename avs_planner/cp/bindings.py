"""Every binding of an action schema's parameters consistent with types, static atoms and
(in)equalities, and the atom codes of lifted atoms under those bindings.

Two implementations of the same join: `join_numpy` (one parameter at a time over columns of
object ids) and `CompiledJoin` (nested loops in C, `avs_planner/cp/_ground.c`). Both give the
rows in lexicographic order of the schema's parameters; `structure.build_structure` picks one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from avs_planner.cp.encoding import AtomSpace, Columns
from avs_planner.cp.schema import AtomTemplate, LiftedSchema
from avs_planner.errors import PlanningError

try:  # the compiled join and encoding; join_numpy and encode_numpy compute the same
    from avs_planner.cp import _ground
except ImportError:
    _ground = None

DENSE_CODES = 1 << 16  # atom code spaces up to this size are tested through a table


def code_set(codes: np.ndarray, space_size: int) -> Callable[[np.ndarray], np.ndarray]:
    """Membership test for a set of atom codes: a lookup table over a small code space (one
    numpy call per test; joins test many times), else a binary search over sorted codes."""
    if space_size <= DENSE_CODES:
        table = np.zeros(space_size, dtype=bool)
        table[codes] = True
        return table.__getitem__
    sorted_codes = np.unique(codes)
    return lambda queries: _member(queries, sorted_codes)


def _member(codes: np.ndarray, sorted_codes: np.ndarray) -> np.ndarray:
    if len(sorted_codes) == 0:
        return np.zeros(len(codes), dtype=bool)
    at = np.minimum(np.searchsorted(sorted_codes, codes), len(sorted_codes) - 1)
    return sorted_codes[at] == codes


def _term_params(terms: Sequence[str]) -> frozenset[str]:
    return frozenset(t for t in terms if t[0] == "?")


def _constraints(schema: LiftedSchema) -> list[tuple[str, tuple, frozenset[str]]]:
    """(kind, atom template or term pair, parameters read) of the schema's static atoms
    ("in", "out") and (in)equalities ("eq", "ne")."""
    return (
        [("in", t, _term_params(t[1:])) for t in schema.static_pos]
        + [("out", t, _term_params(t[1:])) for t in schema.static_neg]
        + [("eq", pair, _term_params(pair)) for pair in schema.equal]
        + [("ne", pair, _term_params(pair)) for pair in schema.not_equal]
    )


def _join_order(schema: LiftedSchema, domain: Mapping[str, np.ndarray],
                constraints: list) -> list[str]:
    """The parameters in join order: next the one closing most constraints, then the one
    with fewest objects, then the first."""
    params = schema.params
    pending = [c for c in constraints if c[2]]
    bound: set[str] = set()
    remaining = list(params)
    chosen: list[str] = []
    while remaining:
        param = min(remaining, key=lambda p: (
            -sum(1 for c in pending if c[2] <= bound | {p}), len(domain[p]), params.index(p)
        ))
        remaining.remove(param)
        chosen.append(param)
        bound.add(param)
        pending = [c for c in pending if not c[2] <= bound]
    return chosen


def join_numpy(
    schema: LiftedSchema, space: AtomSpace, is_static: Callable[[np.ndarray], np.ndarray],
    max_bindings: int,
) -> tuple[dict[str, np.ndarray], int]:
    """Every parameter binding consistent with types, static atoms and (in)equalities, as
    columns of object ids in lexicographic order of the schema's parameters. A join: one
    parameter at a time (`_join_order`), filtering as soon as a constraint's parameters are
    all bound. (`CompiledJoin.bindings` is the same join in C.)"""
    params = schema.params
    domain = {p: space.objects_of(t) for p, t in zip(params, schema.param_types, strict=True)}
    constraints = _constraints(schema)
    columns: dict[str, np.ndarray] = {}
    rows = 1

    def value(term: str, rows: int) -> np.ndarray:
        if term[0] == "?":
            return columns[term]
        return np.full(rows, space.object_id[term], dtype=np.int64)

    def apply(ready: list) -> None:
        nonlocal columns, rows
        mask = None
        for kind, item, _ in ready:
            if kind in ("in", "out"):
                hit = is_static(space.encode_rows(item, columns, rows))
                ok = hit if kind == "in" else ~hit
            else:
                same = value(item[0], rows) == value(item[1], rows)
                ok = same if kind == "eq" else ~same
            mask = ok if mask is None else np.logical_and(mask, ok, out=mask)
        if mask is not None and not mask.all():
            at = np.flatnonzero(mask)
            columns = {p: c[at] for p, c in columns.items()}
            rows = len(at)

    bound: set[str] = set()
    apply([c for c in constraints if not c[2]])
    pending = [c for c in constraints if c[2]]
    chosen = _join_order(schema, domain, constraints)
    for param in chosen:
        if not rows:
            break
        objects = domain[param]
        if rows * len(objects) > max_bindings:
            raise PlanningError(
                f"{schema.what}: more than {max_bindings} partial bindings to ground"
            )
        columns = {p: np.repeat(c, len(objects)) for p, c in columns.items()}
        columns[param] = np.repeat(objects[None, :], rows, axis=0).ravel()  # np.tile, faster
        rows *= len(objects)
        bound.add(param)
        apply([c for c in pending if c[2] <= bound])
        pending = [c for c in pending if not c[2] <= bound]
    if not rows or len(bound) < len(params):
        return {p: np.zeros(0, dtype=np.int64) for p in params}, 0
    if chosen != list(params):  # joined in another order: sort the rows lexicographically
        order = np.lexsort([columns[p] for p in reversed(params)])
        columns = {p: columns[p][order] for p in params}
    return columns, rows


class CompiledJoin:
    """The join and atom encoding of one structure in C (`_ground`): the same rows and codes
    as `join_numpy` and `encode_numpy`, with templates and checks as flat int64 records."""

    def __init__(self, space: AtomSpace, static_codes: np.ndarray):
        self.space = space
        self.n_objects = len(space.names)
        self.dense = space.size <= DENSE_CODES
        if self.dense:
            table = np.zeros(space.size, dtype=np.uint8)
            table[static_codes] = 1
            self.static = table
        else:
            self.static = np.unique(static_codes)
        self._tables: list[np.ndarray] = []
        self._table_at: dict[int, int] = {}  # id of a local table -> its offset
        self._locals = np.zeros(0, dtype=np.int64)

    def _local_offset(self, local: np.ndarray) -> int:
        at = self._table_at.get(id(local))
        if at is None:
            at = self._table_at[id(local)] = len(self._tables) * self.n_objects
            self._tables.append(local)
            self._locals = np.concatenate(self._tables)
        return at

    def _template(self, template: AtomTemplate, index: Mapping[str, int]) -> list[int]:
        """[base, n_terms, (param, stride, local offset) per parameter term]: constants are
        folded into the base as `AtomSpace.encode_rows` folds them."""
        space = self.space
        name = template[0]
        base = space.base[name]
        terms: list[int] = []
        for term_, stride, local in zip(template[1:], space.strides[name], space._locals[name],
                                        strict=True):
            if term_[0] == "?":
                terms += (index[term_], stride, self._local_offset(local))
            else:
                base += stride * int(local[space.object_id[term_]])
        return [base, len(terms) // 3, *terms]

    def bindings(self, schema: LiftedSchema, max_bindings: int, max_rows: int
                 ) -> tuple[np.ndarray, int]:
        """(rows x parameters matrix of object ids, rows) in the parameters' lexicographic
        order; the matrix's columns are the parameters. PlanningError past the limits."""
        space, params = self.space, schema.params
        index = {p: i for i, p in enumerate(params)}
        domain = {p: space.objects_of(t) for p, t in zip(params, schema.param_types, strict=True)}
        constraints = _constraints(schema)
        chosen = _join_order(schema, domain, constraints)
        level = {p: k for k, p in enumerate(chosen)}
        records: list[int] = []
        for kind, item, read in constraints:
            at = max((level[p] for p in read), default=-1)
            if kind in ("in", "out"):
                base, n_terms, *terms = self._template(item, index)
                records += (at, 0 if kind == "in" else 1, n_terms, base, *terms)
            else:
                terms = [index[t] if t[0] == "?" else -1 - space.object_id[t] for t in item]
                records += (at, 2 if kind == "eq" else 3, 2, 0, terms[0], 0, 0, terms[1], 0, 0)
        domains = [domain[p] for p in chosen]
        offsets = np.cumsum([0] + [len(d) for d in domains], dtype=np.int64)
        data, rows, status = _ground.join(
            self.n_objects, offsets, np.concatenate(domains or [np.zeros(0, np.int64)]),
            np.array([index[p] for p in chosen], dtype=np.int64),
            np.array(records, dtype=np.int64), self._locals, self.static, self.dense,
            max_bindings, max_rows,
        )
        if status == 1:
            raise PlanningError(
                f"{schema.what}: more than {max_bindings} partial bindings to ground")
        if status == 2:
            raise PlanningError(f"grounding exceeds {max_rows} actions")
        return np.frombuffer(data, dtype=np.int64).reshape(rows, len(params)), rows

    def codes(self, templates: Sequence[AtomTemplate], index: Mapping[str, int],
              matrix: np.ndarray) -> np.ndarray:
        """`encode_numpy` of the templates under the matrix's rows of bindings."""
        out = np.empty((len(matrix), len(templates)), dtype=np.int64)
        if not templates or not len(matrix):
            return out
        records = [x for t in templates for x in self._template(t, index)]
        _ground.encode(np.ascontiguousarray(matrix), len(matrix), matrix.shape[1],
                       np.array(records, dtype=np.int64), len(templates), self._locals,
                       self.n_objects, out)
        return out


def encode_numpy(templates: Sequence[AtomTemplate], space: AtomSpace, columns: Columns,
           rows: int) -> np.ndarray:
    if not templates:
        return np.empty((rows, 0), dtype=np.int64)
    return np.stack([space.encode_rows(t, columns, rows) for t in templates], axis=1)
