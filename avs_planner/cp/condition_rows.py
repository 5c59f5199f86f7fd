"""A schema's rows for what plain STRIPS rows cannot say: complex conditions and conditional
effects, compiled while the structure is built.

Quantified and disjunctive conditions become CNF per binding (`_complex_rows`): unit clauses
are extra pre/pre_neg codes, longer ones are kept per row, and a binding with an empty clause
is dropped. Conditional effects split each row into copies, one per combination of its
dynamic conditions (`expand_conditional`, over `conditional.py`). Both hand back padded code
arrays in the layout of `fact_rows.py`, so the rest of the build treats every row alike.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.conditional import Variant, expand_rows, variants
from avs_planner.cp.encoding import AtomSpace, Columns
from avs_planner.cp.fact_rows import _PAD_NONE, _PAD_TRUE, _pad
from avs_planner.cp.formulas import FormulaGrounder
from avs_planner.cp.schema import LiftedSchema
from avs_planner.cp.task import Atom
from avs_planner.cp.unsupported import UnsupportedError, in_action, in_rule
from avs_planner.errors import PlanningError

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import FNode


def _read_params(nodes: Sequence[FNode]) -> frozenset[str]:
    """The schema parameters the conditions mention: their CNF depends on nothing else. A
    derived predicate's rule has its lifted `exists` variables among its parameters
    (`?v:name`, as `formulas.py` keys a variable)."""
    stack, read = list(nodes), set()
    while stack:
        node = stack.pop()
        if node.is_parameter_exp():
            read.add("?" + node.parameter().name)
        elif node.is_variable_exp():
            read.add("?v:" + node.variable().name)
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
    except PlanningError as exc:  # name the action (or rule), so the reader can place it
        raise (in_rule(schema.derives, exc) if schema.is_rule
               else in_action(schema.name, exc)) from None
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
            raise PlanningError(f"{schema.what}: cannot ground condition atom {atom}")
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
