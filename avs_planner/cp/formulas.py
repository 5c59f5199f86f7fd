"""Grounding general preconditions (or, imply, forall, exists) into CNF over ground atoms.

Static atoms are decided on the spot; what stays is a list of clauses, each a set of
(atom, polarity) literals. Unit clauses become ordinary STRIPS preconditions; longer ones are
checked clause by clause. `TRUE` is the empty list, `FALSE` a list holding an empty clause.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Mapping

from unified_planning.model import FNode, Type

from avs_planner.cp.task import Atom
from avs_planner.errors import PlanningError

Literal = tuple[Atom, bool]
Clause = frozenset[Literal]
Cnf = list[Clause]
TRUE: Cnf = []
FALSE: Cnf = [frozenset()]
MAX_CLAUSES = 4096


class FormulaGrounder:
    """Grounds one formula under a binding of parameters/variables to object names."""

    def __init__(self, static: frozenset[Atom], static_names: set[str],
                 objects_of: Callable[[Type], list[str]]):
        self.static = static
        self.static_names = static_names
        self.objects_of = objects_of

    def cnf(self, node: FNode, binding: Mapping[str, str], positive: bool = True) -> Cnf:
        if node.is_and() or node.is_or():
            parts = [self.cnf(a, binding, positive) for a in node.args]
            return _and(parts) if node.is_and() == positive else _or(parts)
        if node.is_not():
            return self.cnf(node.arg(0), binding, not positive)
        if node.is_implies():
            left, right = node.arg(0), node.arg(1)
            parts = [self.cnf(left, binding, not positive), self.cnf(right, binding, positive)]
            return _or(parts) if positive else _and(parts)
        if node.is_forall() or node.is_exists():
            return self._quantifier(node, binding, positive)
        if node.is_bool_constant():
            return TRUE if node.bool_constant_value() == positive else FALSE
        if node.is_equals():
            same = self._term(node.arg(0), binding) == self._term(node.arg(1), binding)
            return TRUE if same == positive else FALSE
        if node.is_fluent_exp():
            atom = (node.fluent().name, *(self._term(a, binding) for a in node.args))
            if atom[0] in self.static_names:
                return TRUE if (atom in self.static) == positive else FALSE
            return [frozenset([(atom, positive)])]
        raise PlanningError(f"unsupported condition {node}")

    def _quantifier(self, node: FNode, binding: Mapping[str, str], positive: bool) -> Cnf:
        variables = node.variables()
        domains = [self.objects_of(v.type) for v in variables]
        parts = []
        for values in itertools.product(*domains):
            inner = dict(binding)
            inner.update({"?v:" + v.name: o for v, o in zip(variables, values, strict=True)})
            parts.append(self.cnf(node.arg(0), inner, positive))
        return _and(parts) if node.is_forall() == positive else _or(parts)

    @staticmethod
    def _term(node: FNode, binding: Mapping[str, str]) -> str:
        if node.is_parameter_exp():
            return binding["?" + node.parameter().name]
        if node.is_variable_exp():
            return binding["?v:" + node.variable().name]
        if node.is_object_exp():
            return node.object().name
        raise PlanningError(f"unsupported argument {node}")


def _and(parts: Iterable[Cnf]) -> Cnf:
    clauses: Cnf = []
    for part in parts:
        if part == FALSE:
            return FALSE
        clauses.extend(part)
    return list(dict.fromkeys(clauses))


def _or(parts: Iterable[Cnf]) -> Cnf:
    result: Cnf = FALSE
    for part in parts:
        if part == TRUE:
            return TRUE
        merged = []
        for a in result:
            for b in part:
                clause = a | b
                if not any((atom, not pol) in clause for atom, pol in clause):
                    merged.append(clause)
        result = list(dict.fromkeys(merged))
        if len(result) > MAX_CLAUSES:
            raise PlanningError("a disjunctive precondition grows beyond the CNF size limit")
        if not result:
            return TRUE
    return result
