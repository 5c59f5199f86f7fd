"""Checks of a problem file against its domain: objects, :init, goal, metric, probabilities."""

from __future__ import annotations

from collections.abc import Iterator
from fractions import Fraction
from itertools import product
from typing import TYPE_CHECKING

from avs_planner.errors import PddlError
from avs_planner.pddl.axioms import check_init_fact
from avs_planner.pddl.diagnostics import Diagnostic
from avs_planner.pddl.formulas import FormulaChecker, Usage
from avs_planner.pddl.sexpr import Atom, Node, SList, is_number, parse_sexprs
from avs_planner.pddl.structure import (
    OBJECT,
    Domain,
    Problem,
    Report,
    Typed,
    find_define,
    read_problem,
    typed_list,
)
from avs_planner.pddl.support import numeric_conditions, shown

NEGATIVE_INIT = "negative-init"  # a (not ...) in :init: a warning, then ignored
CONTRADICTORY_INIT = "contradictory-init"  # (not A) and A both in :init: an error

if TYPE_CHECKING:
    from avs_planner.pddl.check import PddlSource

GroundAtom = tuple[str, ...]


def check_problem(domain: Domain, source: PddlSource, usage: Usage) -> list[Diagnostic]:
    """Diagnostics for one problem; goal usage is added to `usage` (requirements, predicates)."""
    report = Report(source.name)
    try:
        nodes = parse_sexprs(source.text, source.name)
    except PddlError as exc:
        return [Diagnostic.from_error(exc)]
    define = find_define(nodes, "problem", report)
    if define is None:
        return report.items
    problem = read_problem(define, report)
    names = {**domain.constants, **problem.objects}
    _check_header(domain, problem, report)
    init_checker = FormulaChecker(domain, report, names, Usage())
    values = _check_init(problem, init_checker)
    if problem.goal is not None:
        FormulaChecker(domain, report, names, usage).goal(problem.goal, {})
        numeric_conditions(problem.goal, report, "unsupported-goal", "the goal")
        _goal_true_in_init(problem, values.atoms, report, domain, names)
    if problem.metric is not None:
        _check_metric(problem.metric, init_checker)
    _check_probabilities(domain, names, problem, usage, values.numbers, report)
    _check_missing_values(domain, names, usage, values.numbers, report, problem.init_node)
    return report.items


class InitValues:
    """The ground atoms and numeric assignments of `:init`."""

    def __init__(self) -> None:
        self.atoms: set[GroundAtom] = set()
        self.numbers: dict[str, list[tuple[SList, Atom]]] = {}


def _check_header(domain: Domain, problem: Problem, report: Report) -> None:
    ref = problem.domain_ref
    if ref is not None and domain.name is not None and ref.text != domain.name.text:
        report.add(
            ref,
            "domain-mismatch",
            f"problem is for domain '{ref.text}' but the domain is '{domain.name.text}'",
        )
    checker = FormulaChecker(domain, report, {}, Usage())
    taken = {**dict.fromkeys(domain.actions, "an action"),
             **dict.fromkeys(domain.functions, "a function"),
             **dict.fromkeys(domain.predicates, "a predicate"),
             **dict.fromkeys(domain.type_atoms, "a type")}
    object_used = _object_type_used(domain)
    for name, entry in problem.objects.items():
        checker.known_type(entry.type_node, entry.type)
        if entry.type == OBJECT and not object_used:
            report.add(
                entry.type_node,
                "untyped-object",
                f"object '{name}' has type 'object', which no predicate, function, constant or "
                "action of the domain uses; give it one of the domain's types",
            )
        if name in domain.constants:
            report.add(entry.atom, "duplicate", f"object '{name}' is already a domain constant")
        elif name in taken:
            report.add(
                entry.atom,
                "name-clash",
                f"object '{name}' has the same name as {taken[name]} (read as Fast Downward "
                "reads it: the names live apart)",
                warning=True,
            )


def _object_type_used(domain: Domain) -> bool:
    """unified-planning only knows the type 'object' when the domain itself uses it."""
    entries = [*domain.constants.values()]
    for sig in [*domain.predicates.values(), *domain.functions.values(), *domain.actions.values()]:
        entries += sig.params
    return any(entry.type == OBJECT for entry in entries)


def _check_init(problem: Problem, checker: FormulaChecker) -> InitValues:
    values = InitValues()
    positive: dict[GroundAtom, SList] = {}  # each true atom where it is first listed
    negative: list[tuple[SList, SList]] = []  # (the (not ...), its atom)
    for fact in problem.init:
        if not isinstance(fact, SList) or not fact.items:
            checker.report.add(fact, "syntax", "expected a ground atom or (= (f ...) VALUE)")
            continue
        check_init_fact(checker.domain, fact, checker.report)
        if fact.head() == "=":
            _init_assignment(fact, checker, values)
        elif fact.head() == "not":
            inner = fact.items[1] if len(fact.items) == 2 else None
            if not isinstance(inner, SList) or not inner.items or inner.head() in ("=", "not"):
                checker.report.add(fact, "syntax", "expected (not (PREDICATE OBJECT ...))")
                continue
            checker.atom(inner, {})
            negative.append((fact, inner))
        else:
            checker.atom(fact, {})
            values.atoms.add(_ground(fact))
            positive.setdefault(_ground(fact), fact)
    for fact, inner in negative:
        _negative_literal(fact, positive.get(_ground(inner)), checker.report)
    return values


def _negative_literal(fact: SList, contradicted: SList | None, report: Report) -> None:
    """As Fast Downward reads it: under the closed world a fact not listed is false, so a
    negative literal says nothing more (a warning); one whose atom is also listed true
    contradicts it (an error naming both places)."""
    if contradicted is None:
        report.add(fact, NEGATIVE_INIT, "a negative literal in :init is ignored: under the "
                   "closed world a fact is false unless listed", warning=True)
        return
    report.add(fact, CONTRADICTORY_INIT, f"{shown(fact)} at {report.file}:{fact.line}:"
               f"{fact.column} contradicts {shown(contradicted)} at {report.file}:"
               f"{contradicted.line}:{contradicted.column}: :init cannot make an atom both "
               "true and false")


def _init_assignment(fact: SList, checker: FormulaChecker, values: InitValues) -> None:
    if len(fact) != 3 or not isinstance(fact.items[1], SList):
        checker.report.add(fact, "syntax", "expected (= (FUNCTION ARGS...) VALUE)")
        return
    term, value = fact.items[1], fact.items[2]
    checker.function_term(term, {})
    if not isinstance(value, Atom) or not is_number(value.text):
        checker.report.add(value, "syntax", "an initial function value must be a number")
        return
    values.numbers.setdefault(term.head(), []).append((term, value))


def _ground(node: SList) -> GroundAtom:
    return tuple(item.text if isinstance(item, Atom) else "()" for item in node.items)


def _check_metric(metric: SList, checker: FormulaChecker) -> None:
    if len(metric) != 3 or not isinstance(metric.items[1], Atom):
        checker.report.add(metric, "syntax", "expected (:metric minimize|maximize EXPRESSION)")
        return
    if metric.items[1].text not in ("minimize", "maximize"):
        checker.report.add(metric.items[1], "syntax", "expected 'minimize' or 'maximize'")
    expression = metric.items[2]
    if not (isinstance(expression, SList) and expression.head() == "total-time"):
        checker.numeric(expression, {})


def _check_probabilities(
    domain: Domain,
    names: dict[str, Typed],
    problem: Problem,
    usage: Usage,
    numbers: dict[str, list[tuple[SList, Atom]]],
    report: Report,
) -> None:
    anchor: Node = problem.init_node or problem.goal_node or Atom("", 1, 1, 0)
    for name in usage.probability_fluents:
        assigned = numbers.get(name, [])
        if not assigned and _groundable(domain, names, name):
            report.add(
                anchor,
                "probability-not-in-init",
                f"probability fluent '{name}' has no value in :init",
            )
        for _term, value in assigned:
            if not 0 <= Fraction(value.text) <= 1:
                report.add(
                    value,
                    "probability-range",
                    f"probability {value.text} for '{name}' is outside [0, 1]",
                )


def _goal_true_in_init(problem: Problem, atoms: set[GroundAtom], report: Report,
                       domain: Domain, names: dict[str, Typed]) -> None:
    """A goal that :init already makes true, judged where that is certain (a goal reading
    derived predicates would need their rules, a numeric one the values: not judged)."""
    if _InitTruth(domain, names, atoms).certain(problem.goal, True, {}):
        report.add(
            problem.goal_node or problem.goal,
            "goal-true-in-init",
            "the goal already holds in :init; the plan will be empty",
            warning=True,
        )


class _InitTruth:
    """Whether a goal description certainly has a truth value in :init (a quantifier over
    the objects of its types; at most MAX_GROUNDINGS atoms are looked at)."""

    def __init__(self, domain: Domain, names: dict[str, Typed], atoms: set[GroundAtom]):
        self.domain = domain
        self.names = names
        self.atoms = atoms
        self.budget = MAX_GROUNDINGS

    def certain(self, node: Node | None, value: bool, binding: dict[str, str]) -> bool:
        """True if `node` certainly evaluates to `value` under `binding` in :init."""
        if not isinstance(node, SList) or not node.items or self.budget <= 0:
            return False
        head, args = node.head(), node.items[1:]
        if head in ("and", "or"):
            every = (head == "and") == value  # (and) true / (or) false: every part must be
            parts = (self.certain(child, value, binding) for child in args)
            return all(parts) if every else any(parts)
        if head == "not" and len(args) == 1:
            return self.certain(args[0], not value, binding)
        if head == "imply" and len(args) == 2:
            left = self.certain(args[0], not value, binding)
            return (left or self.certain(args[1], True, binding)) if value else (
                left and self.certain(args[1], False, binding))
        if head in ("forall", "exists") and len(args) == 2 and isinstance(args[0], SList):
            every = (head == "forall") == value
            parts = (self.certain(args[1], value, inner)
                     for inner in self._bindings(args[0], binding))
            return all(parts) if every else any(parts)
        if head == "=" and len(args) == 2 and all(isinstance(a, Atom) for a in args):
            left, right = (binding.get(a.text, a.text) for a in args)  # type: ignore[union-attr]
            return (left == right) == value
        if head in self.domain.derived_names or head not in self.domain.predicates:
            return False  # a derived predicate, a comparison, or an error reported elsewhere
        if not all(isinstance(a, Atom) for a in args):
            return False
        self.budget -= 1
        atom = (head, *(binding.get(a.text, a.text) for a in args))  # type: ignore[union-attr]
        return (atom in self.atoms) == value

    def _bindings(self, variables: SList, binding: dict[str, str]
                  ) -> Iterator[dict[str, str]]:
        entries = typed_list(variables.items, Report(""))
        pools = [[n for n, e in self.names.items() if self.domain.is_subtype(e.type, v.type)]
                 for v in entries]
        for values in product(*pools):
            inner = dict(binding)
            inner.update(zip((v.name for v in entries), values, strict=True))
            yield inner


MAX_GROUNDINGS = 100_000


def _check_missing_values(
    domain: Domain,
    names: dict[str, Typed],
    usage: Usage,
    numbers: dict[str, list[tuple[SList, Atom]]],
    report: Report,
    anchor: SList | None,
) -> None:
    """Every ground instance of a used function needs an :init value; UP planners reject
    problems with undefined numeric values. Missing probabilities are errors."""
    used = {name for name, _ in usage.changed_functions} | set(usage.probability_fluents)
    used |= usage.cost_functions
    for name in sorted(used & set(domain.functions)):
        if name not in numbers or name == "total-cost":
            continue  # wholly absent probability fluents are reported by _check_probabilities
        missing = _missing(domain, names, name, numbers[name])
        if missing:
            first, count = missing
            is_probability = name in usage.probability_fluents
            report.add(
                anchor or Atom("", 1, 1, 0),
                "probability-not-in-init" if is_probability else "missing-init-value",
                f"no :init value for ({name} {' '.join(first)})"
                + (f" and {count - 1} more instance(s)" if count > 1 else ""),
                warning=not is_probability,
            )


def _groundable(domain: Domain, names: dict[str, Typed], name: str) -> bool:
    """Whether the function has a ground instance at all (an object for every parameter);
    one over a type with no objects (no placeholders left, say) needs no :init value."""
    function = domain.functions.get(name)
    if function is None:
        return True
    return all(any(domain.is_subtype(e.type, p.type) for e in names.values())
               for p in function.params)


def _missing(
    domain: Domain, names: dict[str, Typed], name: str, assigned: list[tuple[SList, Atom]]
) -> tuple[tuple[str, ...], int] | None:
    """The first ground instance without a value and how many there are, or None."""
    params = domain.functions[name].params
    pools = [[n for n, e in names.items() if domain.is_subtype(e.type, p.type)] for p in params]
    total = 1
    for pool in pools:
        total *= len(pool)
    if total > MAX_GROUNDINGS:
        return None
    given = {tuple(_ground(term)[1:]) for term, _ in assigned}
    missing = [args for args in product(*pools) if args not in given]
    return (missing[0], len(missing)) if missing else None
