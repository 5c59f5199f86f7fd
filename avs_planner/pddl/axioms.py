"""Checks of derived predicates (PDDL 2.2 `:derived`), with positions, for `avs domain check`
and the reader alike.

A rule `(:derived (p ?x - t ...) BODY)` defines p for every binding of its variables where
BODY holds; several rules for one predicate are a disjunction. The checks: the head names a
declared predicate with the right arity and types, the body is a goal description over the
head's variables (as a precondition is), the rules are stratified (`stratify.py`: no
negation inside a cycle of derived predicates), and no action effect and no `:init` entry
sets a derived predicate (its truth follows from the rules in every state).
"""

from __future__ import annotations

from collections.abc import Iterator

from avs_planner.pddl.diagnostics import did_you_mean
from avs_planner.pddl.formulas import FormulaChecker
from avs_planner.pddl.sexpr import Atom, Node, SList
from avs_planner.pddl.structure import Action, DerivedRule, Domain, Report
from avs_planner.pddl.support import UNSUPPORTED_CONDITION, numeric_conditions

REQUIREMENT = ":derived-predicates"
NOT_STRATIFIED = "not-stratified"
DERIVED_IN_EFFECT = "derived-in-effect"
DERIVED_IN_INIT = "derived-in-init"
Occurrence = tuple[str, bool, SList]  # (derived predicate, negated, the atom's node)


def check_derived(domain: Domain, report: Report, checker: FormulaChecker) -> None:
    """Heads, bodies and stratification of the domain's rules."""
    for rule in domain.derived:
        checker.usage.need(REQUIREMENT, report.file, rule.node)
        scope = _head(domain, rule, report, checker)
        if rule.body is not None and scope is not None:
            checker.goal(rule.body, scope)
            numeric_conditions(rule.body, report, UNSUPPORTED_CONDITION,
                               f"the rule for derived predicate '{rule.atom.text}'")
    _stratification(domain, report)
    for action in domain.actions.values():
        _effects(domain, action, report)


def _head(domain: Domain, rule: DerivedRule, report: Report,
          checker: FormulaChecker) -> dict[str, str] | None:
    """The head's variables as a scope for the body, or None when the head is wrong."""
    name = rule.atom.text
    sig = domain.predicates.get(name)
    if sig is None:
        what = ("a function, not a predicate" if name in domain.functions
                else "not a declared predicate" + did_you_mean(name, domain.predicates))
        report.add(rule.atom, "unknown-predicate",
                   f"the derived predicate '{name}' is {what} (declare it in :predicates)")
        return None
    head = rule.node.items[1]
    if len(rule.params) != len(sig.params):
        report.add(head, "wrong-arity", f"derived predicate '{name}' takes "
                   f"{len(sig.params)} argument(s), the rule's head has {len(rule.params)}")
        return None
    scope: dict[str, str] = {}
    for param, declared in zip(rule.params, sig.params, strict=True):
        checker.known_type(param.type_node, param.type)
        if param.name in scope:
            report.add(param.atom, "duplicate", f"variable '{param.name}' appears twice in "
                       f"the head of the rule for '{name}'")
        elif not domain.is_subtype(param.type, declared.type):
            report.add(param.type_node, "type-mismatch", f"'{param.name}' has type "
                       f"'{param.type}' but predicate '{name}' expects '{declared.type}' here")
        scope[param.name] = param.type
    return scope


def occurrences(node: Node, derived: frozenset[str], negated: bool = False
                ) -> Iterator[Occurrence]:
    """The derived predicates a goal description names, with their polarity: `not` and an
    `imply`'s antecedent flip it; `and`, `or`, `forall` and `exists` keep it."""
    if not isinstance(node, SList) or not node.items:
        return
    head = node.head()
    if head in ("and", "or"):
        for child in node.items[1:]:
            yield from occurrences(child, derived, negated)
    elif head == "not" and len(node) == 2:
        yield from occurrences(node.items[1], derived, not negated)
    elif head == "imply" and len(node) == 3:
        yield from occurrences(node.items[1], derived, not negated)
        yield from occurrences(node.items[2], derived, negated)
    elif head in ("forall", "exists") and len(node) == 3:
        yield from occurrences(node.items[2], derived, negated)
    elif head in derived:
        yield head, negated, node


def _stratification(domain: Domain, report: Report) -> None:
    """One error per negation inside a cycle, at the negated atom, naming the cycle."""
    derived = domain.derived_names
    if not derived:
        return
    from avs_planner.pddl.stratify import stratify  # only domains with rules need it
    found: dict[str, list[Occurrence]] = {name: [] for name in derived}
    for rule in domain.derived:
        if rule.atom.text in derived and rule.body is not None:
            found[rule.atom.text] += occurrences(rule.body, derived)
    _strata, violations = stratify({p: [(q, neg) for q, neg, _ in occ]
                                    for p, occ in found.items()})
    for violation in violations:
        for q, negated, node in found[violation.head]:
            if q == violation.body and negated:
                report.add(node, NOT_STRATIFIED, f"derived predicate '{q}' is negated in "
                           f"the rule for '{violation.head}', which it depends on in turn "
                           f"({' -> '.join(violation.cycle)}): negation inside a cycle of "
                           "derived predicates cannot be stratified")


def _effects(domain: Domain, action: Action, report: Report) -> None:
    derived = domain.derived_names
    if not derived or action.effect is None:
        return
    for node in _effect_atoms(action.effect):
        name = node.head()
        if name in derived:
            report.add(node, DERIVED_IN_EFFECT, f"action '{action.atom.text}' changes the "
                       f"derived predicate '{name}', whose truth follows from its :derived "
                       "rules (derived predicates may appear in conditions only)")


def _effect_atoms(node: Node) -> Iterator[SList]:
    """The atoms an effect adds or deletes (not those its `when` conditions read)."""
    if not isinstance(node, SList) or not node.items:
        return
    head = node.head()
    if head == "and":
        for child in node.items[1:]:
            yield from _effect_atoms(child)
    elif head == "not" and len(node) == 2:
        yield from _effect_atoms(node.items[1])
    elif head in ("forall", "when", "probabilistic") and len(node) == 3:
        yield from _effect_atoms(node.items[2])
    elif isinstance(node.items[0], Atom):
        yield node


def check_init_fact(domain: Domain, fact: SList, report: Report) -> None:
    """A derived predicate in `:init` (true or negated) is an error, at the fact."""
    inner = fact.items[1] if fact.head() == "not" and len(fact) == 2 else fact
    if isinstance(inner, SList) and inner.head() in domain.derived_names:
        report.add(fact, DERIVED_IN_INIT, f"derived predicate '{inner.head()}' in :init: its "
                   "truth follows from its :derived rules (list the facts they read instead)")
