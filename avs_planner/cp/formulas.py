"""Grounding general preconditions (or, imply, forall, exists) into CNF over ground atoms.

Static atoms are decided on the spot; what stays is a list of clauses, each a set of
(atom, polarity) literals. Unit clauses become ordinary STRIPS preconditions; longer ones are
checked clause by clause. `TRUE` is the empty list, `FALSE` a list holding an empty clause.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING

from avs_planner.cp.task import Atom
from avs_planner.errors import PlanningError

if TYPE_CHECKING:  # nodes of UP's model or of the project's own (`pddl.lite`): same methods
    from unified_planning.model import FNode, Type

Literal = tuple[Atom, bool]
Clause = frozenset[Literal]
Cnf = list[Clause]
TRUE: Cnf = []
FALSE: Cnf = [frozenset()]
MAX_CLAUSES = 4096
# node kinds by the name of their `node_type` (UP's `OperatorKind`, or `lite`'s of the
# same names)
_FLUENT, _AND, _OR, _NOT = "FLUENT_EXP", "AND", "OR", "NOT"
_IMPLIES, _FORALL, _EXISTS = "IMPLIES", "FORALL", "EXISTS"
_BOOL, _EQUALS = "BOOL_CONSTANT", "EQUALS"
_PARAM, _VARIABLE, _OBJECT = "PARAM_EXP", "VARIABLE_EXP", "OBJECT_EXP"
_TERMS = (_PARAM, _VARIABLE, _OBJECT)
_COMPARISONS = ("LT", "LE")  # UP reads > and >= as < and <= swapped


def unsupported_condition(node: FNode, what: str) -> str:
    """The message for a condition the grounder cannot take, naming its kind."""
    return (f"unsupported condition {node} ({what}; conditions are atoms, equality of "
            "objects, and, or, not, imply, forall and exists)")


class FormulaGrounder:
    """Grounds one formula under a binding of parameters/variables to object names.

    Each formula is compiled once into nested closures (its node kinds, fluent names,
    argument keys and quantifier domains read from the nodes up front), which are then
    called per binding: reading the nodes again for each binding cost more than the
    grounding itself on quantified conditions."""

    def __init__(self, static: frozenset[Atom], static_names: set[str],
                 objects_of: Callable[[Type], list[str]]):
        self.static = static
        self.static_names = static_names
        self.objects_of = objects_of
        self._compiled: dict[int, tuple[FNode, _Grounding]] = {}

    def cnf(self, node: FNode, binding: Mapping[str, str], positive: bool = True) -> Cnf:
        hit = self._compiled.get(id(node))
        if hit is None or hit[0] is not node:
            hit = self._compiled[id(node)] = (node, self._compile(node))  # a strong ref
        return hit[1](binding, positive)

    def _compile(self, node: FNode) -> _Grounding:
        kind = node.node_type.name
        if kind == _FLUENT:
            return self._fluent(node)
        if kind == _AND or kind == _OR:
            parts = [self._compile(a) for a in node.args]
            conjunction = kind == _AND

            def junction(binding, positive):
                cnfs = [p(binding, positive) for p in parts]
                return _and(cnfs) if conjunction == positive else _or(cnfs)
            return junction
        if kind == _NOT:
            inner = self._compile(node.arg(0))
            return lambda binding, positive: inner(binding, not positive)
        if kind == _IMPLIES:
            left, right = self._compile(node.arg(0)), self._compile(node.arg(1))

            def implies(binding, positive):
                cnfs = [left(binding, not positive), right(binding, positive)]
                return _or(cnfs) if positive else _and(cnfs)
            return implies
        if kind == _FORALL or kind == _EXISTS:
            return self._quantifier(node)
        if kind == _BOOL:
            value = node.bool_constant_value()
            return lambda binding, positive: TRUE if value == positive else FALSE
        if kind == _EQUALS:
            if not all(a.node_type.name in _TERMS for a in node.args):
                raise PlanningError(unsupported_condition(node, "numeric equality"))
            left, right = _term(node.arg(0)), _term(node.arg(1))

            def equals(binding, positive):
                return TRUE if (_value(left, binding) == _value(right, binding)) == positive \
                    else FALSE
            return equals
        what = "a numeric comparison" if kind in _COMPARISONS else kind.lower()
        raise PlanningError(unsupported_condition(node, what))

    def _fluent(self, node: FNode) -> _Grounding:
        name = node.fluent().name
        terms = tuple(_term(a) for a in node.args)
        if name in self.static_names:
            static = self.static

            def static_atom(binding, positive):
                atom = (name, *[_value(t, binding) for t in terms])
                return TRUE if (atom in static) == positive else FALSE
            return static_atom

        def atom(binding, positive):
            return [frozenset([((name, *[_value(t, binding) for t in terms]), positive)])]
        return atom

    def _quantifier(self, node: FNode) -> _Grounding:
        variables = node.variables()
        domains = [self.objects_of(v.type) for v in variables]
        keys = ["?v:" + v.name for v in variables]
        body = self._compile(node.arg(0))
        forall = node.is_forall()

        def quantifier(binding, positive):
            parts = []
            for values in itertools.product(*domains):
                inner = dict(binding)
                inner.update(zip(keys, values, strict=True))
                parts.append(body(inner, positive))
            return _and(parts) if forall == positive else _or(parts)
        return quantifier


_Grounding = Callable[[Mapping[str, str], bool], Cnf]
_Term = tuple[str | None, str | None]  # (binding key, None) or (None, object name)


def _term(node: FNode) -> _Term:
    kind = node.node_type.name
    if kind == _PARAM:
        return "?" + node.parameter().name, None
    if kind == _VARIABLE:
        return "?v:" + node.variable().name, None
    if kind == _OBJECT:
        return None, node.object().name
    raise PlanningError(f"unsupported argument {node}")


def _value(term: _Term, binding: Mapping[str, str]) -> str:
    key, name = term
    return binding[key] if key is not None else name  # type: ignore[return-value]


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
