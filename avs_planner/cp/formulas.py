"""Grounding general preconditions (or, imply, forall, exists) into CNF over ground atoms.

Static atoms are decided on the spot; what stays is a list of clauses, each a set of
(atom, polarity) literals. Unit clauses become ordinary STRIPS preconditions; longer ones are
checked clause by clause. `TRUE` is the empty list, `FALSE` a list holding an empty clause.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Mapping

from unified_planning.model import FNode, OperatorKind, Type

from avs_planner.cp.task import Atom
from avs_planner.errors import PlanningError

Literal = tuple[Atom, bool]
Clause = frozenset[Literal]
Cnf = list[Clause]
TRUE: Cnf = []
FALSE: Cnf = [frozenset()]
MAX_CLAUSES = 4096
_FLUENT, _AND, _OR, _NOT = (OperatorKind.FLUENT_EXP, OperatorKind.AND, OperatorKind.OR,
                            OperatorKind.NOT)
_IMPLIES, _FORALL, _EXISTS = OperatorKind.IMPLIES, OperatorKind.FORALL, OperatorKind.EXISTS
_BOOL, _EQUALS = OperatorKind.BOOL_CONSTANT, OperatorKind.EQUALS
_PARAM, _VARIABLE, _OBJECT = (OperatorKind.PARAM_EXP, OperatorKind.VARIABLE_EXP,
                              OperatorKind.OBJECT_EXP)


class FormulaGrounder:
    """Grounds one formula under a binding of parameters/variables to object names."""

    def __init__(self, static: frozenset[Atom], static_names: set[str],
                 objects_of: Callable[[Type], list[str]]):
        self.static = static
        self.static_names = static_names
        self.objects_of = objects_of

    def cnf(self, node: FNode, binding: Mapping[str, str], positive: bool = True) -> Cnf:
        # One read of the node's kind, most frequent kinds first: a chain of `is_...()`
        # calls cost more than the grounding itself on quantified conditions.
        kind = node.node_type
        if kind is _FLUENT:
            atom = (node.fluent().name, *(self._term(a, binding) for a in node.args))
            if atom[0] in self.static_names:
                return TRUE if (atom in self.static) == positive else FALSE
            return [frozenset([(atom, positive)])]
        if kind is _AND or kind is _OR:
            parts = [self.cnf(a, binding, positive) for a in node.args]
            return _and(parts) if (kind is _AND) == positive else _or(parts)
        if kind is _NOT:
            return self.cnf(node.arg(0), binding, not positive)
        if kind is _IMPLIES:
            left, right = node.arg(0), node.arg(1)
            parts = [self.cnf(left, binding, not positive), self.cnf(right, binding, positive)]
            return _or(parts) if positive else _and(parts)
        if kind is _FORALL or kind is _EXISTS:
            return self._quantifier(node, binding, positive)
        if kind is _BOOL:
            return TRUE if node.bool_constant_value() == positive else FALSE
        if kind is _EQUALS:
            same = self._term(node.arg(0), binding) == self._term(node.arg(1), binding)
            return TRUE if same == positive else FALSE
        raise PlanningError(f"unsupported condition {node}")

    def _quantifier(self, node: FNode, binding: Mapping[str, str], positive: bool) -> Cnf:
        variables = node.variables()
        domains = [self.objects_of(v.type) for v in variables]
        keys = ["?v:" + v.name for v in variables]
        body = node.arg(0)
        parts = []
        for values in itertools.product(*domains):
            inner = dict(binding)
            inner.update(zip(keys, values, strict=True))
            parts.append(self.cnf(body, inner, positive))
        return _and(parts) if node.is_forall() == positive else _or(parts)

    @staticmethod
    def _term(node: FNode, binding: Mapping[str, str]) -> str:
        kind = node.node_type
        if kind is _PARAM:
            return binding["?" + node.parameter().name]
        if kind is _VARIABLE:
            return binding["?v:" + node.variable().name]
        if kind is _OBJECT:
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
