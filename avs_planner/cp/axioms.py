"""Derived predicates' rules (PDDL 2.2 `:derived`) compiled into rule schemas, which the
grounder joins, reaches and numbers like actions (`structure.py`).

A rule `p(x) <- BODY` becomes one `LiftedSchema` per disjunct of BODY's lifted disjunctive
normal form: negations are pushed to the atoms, `or` (and `imply`) split into separate
schemas, and the variables of an `exists` (not under a negation) become parameters of the
schema (`?v:name`, as `formulas.py` keys a variable), so the join binds them over the static
atoms as it binds an action's parameters. What stays (a `forall`, a negated `exists`, a
variable an `exists` binds twice in one disjunct, a disjunction whose expansion would pass
MAX_DISJUNCTS) is kept as a complex condition and grounded to clauses per binding, as an
action's `forall` precondition is. The schema's `add` is the head; its cost 0, its success
probability 1.

The rules' strata (`pddl.stratify`) order them for the closure (`ground_axioms.py`); rules
that cannot be stratified are refused, naming the predicates (the reader's check reports
them at their position first).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

from avs_planner.cp.encoding import compile_vector
from avs_planner.cp.formulas import unsupported_condition
from avs_planner.cp.schema import AtomTemplate, LiftedSchema, Term, axioms_of, derived_names
from avs_planner.cp.unsupported import UnsupportedError, in_rule
from avs_planner.errors import PlanningError
from avs_planner.pddl.stratify import stratify

if TYPE_CHECKING:  # the project's own model (`pddl.lite`): UP 1.3's has no axioms
    from avs_planner.pddl.lite import Axiom, FNode, Problem, Type

MAX_DISJUNCTS = 64  # rule schemas one rule's body may split into
RULE_PREFIX = ":derived "  # a rule schema's name: no PDDL action name starts with ':'


def compile_axioms(problem: Problem, static_names: frozenset[str]
                   ) -> tuple[LiftedSchema, ...]:
    """The rule schemas of every rule, with their strata; raises `UnsupportedError` naming
    the derived predicate for what cannot be grounded or stratified."""
    axioms = axioms_of(problem)
    if not axioms:
        return ()
    names = derived_names(problem)
    dependencies: dict[str, list[tuple[str, bool]]] = {name: [] for name in names}
    for axiom in axioms:
        dependencies[axiom.name] += occurrences(axiom.body, names)
    strata, violations = stratify(dependencies)
    if violations:
        v = violations[0]
        raise UnsupportedError(
            f"derived predicate {v.body} is negated in a rule for {v.head}, which it "
            f"depends on in turn ({' -> '.join(v.cycle)}): negation inside a cycle of "
            "derived predicates cannot be stratified", rule=v.head)
    em = problem.environment.expression_manager
    schemas: list[LiftedSchema] = []
    for k, axiom in enumerate(axioms):
        try:
            disjuncts = _Normalizer(em).dnf(axiom.body, True, frozenset())
        except PlanningError as exc:
            raise in_rule(axiom.name, exc) from None
        for j, conj in enumerate(disjuncts):
            schemas.append(_schema(axiom, f"{RULE_PREFIX}{axiom.name} #{k}.{j}", conj,
                                   static_names, strata[axiom.name]))
    return tuple(schemas)


def occurrences(node: FNode, derived: frozenset[str], negated: bool = False
                ) -> Iterator[tuple[str, bool]]:
    """The derived predicates a body names, with their polarity (as `pddl/axioms.py` reads
    the text: `not` and an `imply`'s antecedent flip it)."""
    kind = node.node_type.name
    if kind == "FLUENT_EXP":
        if node.fluent().name in derived:
            yield node.fluent().name, negated
    elif kind == "NOT":
        yield from occurrences(node.arg(0), derived, not negated)
    elif kind == "IMPLIES":
        yield from occurrences(node.arg(0), derived, not negated)
        yield from occurrences(node.arg(1), derived, negated)
    else:
        for arg in node.args:
            yield from occurrences(arg, derived, negated)


@dataclass(frozen=True)
class _Conj:
    """One disjunct: literals, (in)equalities, lifted variables and complex conditions."""

    literals: tuple[tuple[AtomTemplate, bool], ...] = ()
    equalities: tuple[tuple[Term, Term, bool], ...] = ()
    variables: tuple[tuple[str, Type], ...] = ()
    complex: tuple[FNode, ...] = ()

    def __add__(self, other: _Conj) -> _Conj:
        return _Conj(self.literals + other.literals, self.equalities + other.equalities,
                     self.variables + other.variables, self.complex + other.complex)


class _Normalizer:
    """The lifted DNF of a rule body (see the module docstring)."""

    def __init__(self, em: object):
        self.em = em

    def dnf(self, node: FNode, positive: bool, taken: frozenset[str]) -> list[_Conj]:
        """Disjuncts of `node` (negated unless `positive`); `taken`: the variables lifted
        around it (an `exists` binding one of them again is kept complex)."""
        kind = node.node_type.name
        if kind == "FLUENT_EXP":
            return [_Conj(literals=((_template(node), positive),))]
        if kind == "NOT":
            return self.dnf(node.arg(0), not positive, taken)
        if kind in ("AND", "OR"):
            if (kind == "AND") == positive:
                return self._conjunction([(a, positive) for a in node.args], taken)
            return [c for a in node.args for c in self.dnf(a, positive, taken)]
        if kind == "IMPLIES":
            left, right = node.arg(0), node.arg(1)
            if positive:
                return self.dnf(left, False, taken) + self.dnf(right, True, taken)
            return self._conjunction([(left, True), (right, False)], taken)
        if kind in ("EXISTS", "FORALL"):
            keys = tuple("?v:" + v.name for v in node.variables())
            if (kind == "EXISTS") != positive or not taken.isdisjoint(keys):
                return [self._complex(node, positive)]
            lifted = _Conj(variables=tuple(zip(keys, (v.type for v in node.variables()),
                                               strict=True)))
            return [lifted + c for c in self.dnf(node.arg(0), positive, taken | set(keys))]
        if kind == "BOOL_CONSTANT":
            return [_Conj()] if node.bool_constant_value() == positive else []
        if kind == "EQUALS":
            if not all(a.node_type.name in _TERMS for a in node.args):
                raise PlanningError(unsupported_condition(node, "numeric equality"))
            left, right = (_term(a) for a in node.args)
            return [_Conj(equalities=((left, right, positive),))]
        what = "a numeric comparison" if kind in ("LT", "LE") else kind.lower()
        raise PlanningError(unsupported_condition(node, what))

    def _conjunction(self, parts: Iterable[tuple[FNode, bool]], taken: frozenset[str]
                     ) -> list[_Conj]:
        result = [_Conj()]
        for node, positive in parts:
            found = self.dnf(node, positive, taken)
            if len(result) * len(found) > MAX_DISJUNCTS:
                found = [self._complex(node, positive)]  # grounded to clauses instead
            taken = taken | {k for c in found for k, _ in c.variables}
            result = [a + b for a in result for b in found]
        return result

    def _complex(self, node: FNode, positive: bool) -> _Conj:
        return _Conj(complex=(node if positive else self.em.Not(node),))  # type: ignore[attr-defined]


_TERMS = ("PARAM_EXP", "VARIABLE_EXP", "OBJECT_EXP")


def _term(node: FNode) -> Term:
    kind = node.node_type.name
    if kind == "PARAM_EXP":
        return "?" + node.parameter().name
    if kind == "VARIABLE_EXP":
        return "?v:" + node.variable().name
    if kind == "OBJECT_EXP":
        return node.object().name
    raise PlanningError(f"unsupported argument {node}")


def _template(node: FNode) -> AtomTemplate:
    return (node.fluent().name, *(_term(a) for a in node.args))


def _schema(axiom: Axiom, name: str, conj: _Conj, static_names: frozenset[str],
            stratum: int) -> LiftedSchema:
    params = {"?" + p.name: p.type for p in axiom.parameters}
    for key, type_ in conj.variables:
        params.setdefault(key, type_)
    parts: dict[tuple[bool, bool], list[AtomTemplate]] = {
        (s, p): [] for s in (True, False) for p in (True, False)}
    for template, positive in dict.fromkeys(conj.literals):
        parts[(template[0] in static_names, positive)].append(template)
    equalities = dict.fromkeys(conj.equalities)
    return LiftedSchema(
        name=name, params=tuple(params), param_types=tuple(params.values()),
        static_pos=tuple(parts[(True, True)]), static_neg=tuple(parts[(True, False)]),
        pre_pos=tuple(parts[(False, True)]), pre_neg=tuple(parts[(False, False)]),
        equal=tuple((a, b) for a, b, positive in equalities if positive),
        not_equal=tuple((a, b) for a, b, positive in equalities if not positive),
        add=((axiom.name, *("?" + p.name for p in axiom.parameters)),), delete=(),
        cost=compile_vector(None, "", 0.0), probability=compile_vector(None, "", 1.0),
        complex=tuple(dict.fromkeys(conj.complex)), derives=axiom.name, stratum=stratum,
    )
