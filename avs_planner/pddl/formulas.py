"""Check preconditions, goals and effects against a domain's declarations.

Walks the formula trees with the variables in scope and records what the linter needs later:
requirements actually used, predicates referenced, probability fluents and changed functions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

from avs_planner.pddl.diagnostics import did_you_mean
from avs_planner.pddl.sexpr import Atom, Node, SList, is_number
from avs_planner.pddl.structure import Domain, Report, Typed, typed_list

COMPARISONS = {"<", ">", "<=", ">="}
ARITHMETIC = {"+", "-", "*", "/"}
ASSIGNMENTS = {"increase", "decrease", "assign", "scale-up", "scale-down"}
TOTAL_COST = "total-cost"


@dataclass
class Usage:
    """What the formulas of a domain (and its problems) use."""

    requirements: dict[str, tuple[str, Node]] = field(default_factory=dict)
    predicates: set[str] = field(default_factory=set)
    probability_fluents: dict[str, SList] = field(default_factory=dict)
    changed_functions: list[tuple[str, SList]] = field(default_factory=list)
    cost_functions: set[str] = field(default_factory=set)

    def need(self, requirement: str, file: str, node: Node) -> None:
        self.requirements.setdefault(requirement, (file, node))


@dataclass
class FormulaChecker:
    """Checks formulas of one file; `names` are the constants/objects visible there."""

    domain: Domain
    report: Report
    names: dict[str, Typed]
    usage: Usage

    def _need(self, requirement: str, node: Node) -> None:
        self.usage.need(requirement, self.report.file, node)

    # ---- goal descriptions -------------------------------------------------------------

    def goal(self, node: Node, scope: dict[str, str]) -> None:
        """A precondition or goal formula."""
        if not isinstance(node, SList):
            self.report.add(node, "syntax", f"expected a formula in parentheses, not '{node.text}'")
            return
        head = node.head()
        if not node.items:
            return
        if head in ("and", "or"):
            if head == "or":
                self._need(":disjunctive-preconditions", node)
            for child in node.items[1:]:
                self.goal(child, scope)
        elif head == "not":
            self._need(":negative-preconditions", node)
            if self._fixed(node, 1):
                self.goal(node.items[1], scope)
        elif head == "imply":
            self._need(":disjunctive-preconditions", node)
            if self._fixed(node, 2):
                self.goal(node.items[1], scope)
                self.goal(node.items[2], scope)
        elif head in ("forall", "exists"):
            kind = "universal" if head == "forall" else "existential"
            self._need(f":{kind}-preconditions", node)
            inner = self._quantified(node, scope)
            if inner is not None:
                self.goal(node.items[2], inner)
        elif head == "=":
            self._equality(node, scope)
        elif head in COMPARISONS:
            self._need(":numeric-fluents", node)
            if self._fixed(node, 2):
                self.numeric(node.items[1], scope)
                self.numeric(node.items[2], scope)
        else:
            self.atom(node, scope)

    def _fixed(self, node: SList, count: int) -> bool:
        if len(node) - 1 != count:
            self.report.add(
                node, "syntax", f"'{node.head()}' takes {count} argument(s), got {len(node) - 1}"
            )
            return False
        return True

    def _quantified(self, node: SList, scope: dict[str, str]) -> dict[str, str] | None:
        if not self._fixed(node, 2) or not isinstance(node.items[1], SList):
            if len(node) == 3:
                self.report.add(node.items[1], "syntax", "expected a variable list (?x - type)")
            return None
        inner = dict(scope)
        for entry in typed_list(node.items[1].items, self.report):
            self._variable(entry)
            inner[entry.name] = entry.type
        return inner

    def _variable(self, entry: Typed) -> None:
        self.known_type(entry.type_node, entry.type)

    def known_type(self, node: Node, type_name: str) -> None:
        """Report a type that is not declared."""
        if type_name not in self.domain.types:
            hint = did_you_mean(type_name, self.domain.types)
            self.report.add(node, "unknown-type", f"unknown type '{type_name}'{hint}")

    def _equality(self, node: SList, scope: dict[str, str]) -> None:
        if not self._fixed(node, 2):
            return
        left, right = node.items[1], node.items[2]
        if self._is_numeric(left) or self._is_numeric(right):
            self._need(":numeric-fluents", node)
            self.numeric(left, scope)
            self.numeric(right, scope)
            return
        self._need(":equality", node)
        for term in (left, right):
            self.term(term, scope)

    def _is_numeric(self, node: Node) -> bool:
        if isinstance(node, Atom):
            return is_number(node.text)
        return node.head() in self.domain.functions or node.head() in ARITHMETIC

    # ---- atoms and terms ---------------------------------------------------------------

    def atom(self, node: SList, scope: dict[str, str]) -> None:
        """A predicate application: known predicate, right arity, right argument types."""
        head = node.items[0]
        if not isinstance(head, Atom):
            self.report.add(node, "syntax", "expected a predicate name")
            return
        sig = self.domain.predicates.get(head.text)
        if sig is None:
            self._unknown_predicate(head)
            return
        self.usage.predicates.add(head.text)
        self.arguments(node, sig.params, scope, "predicate")

    def _unknown_predicate(self, head: Atom) -> None:
        if head.text in self.domain.functions:
            msg = f"'{head.text}' is a function, not a predicate"
        else:
            msg = f"unknown predicate '{head.text}'" + did_you_mean(
                head.text, self.domain.predicates
            )
        self.report.add(head, "unknown-predicate", msg)

    def arguments(self, node: SList, params: list[Typed], scope: dict[str, str], what: str) -> None:
        """Arity and argument types of a predicate or function application."""
        args = node.items[1:]
        if len(args) != len(params):
            self.report.add(
                node,
                "wrong-arity",
                f"{what} '{node.head()}' takes {len(params)} argument(s), got {len(args)}",
            )
            return
        for arg, param in zip(args, params, strict=True):
            actual = self.term(arg, scope)
            if actual is not None and not self.domain.is_subtype(actual, param.type):
                self.report.add(
                    arg,
                    "type-mismatch",
                    f"'{arg.text}' has type '{actual}' but {what} '{node.head()}' expects "
                    f"'{param.type}' here",
                )

    def term(self, node: Node, scope: dict[str, str]) -> str | None:
        """The type of a term (variable or constant/object), or None after reporting."""
        if isinstance(node, SList):
            self.report.add(node, "syntax", "expected a variable or an object name here")
            return None
        if node.text.startswith("?"):
            if node.text not in scope:
                hint = did_you_mean(node.text, scope)
                self.report.add(
                    node, "unbound-variable", f"variable '{node.text}' is not bound{hint}"
                )
                return None
            return scope[node.text]
        entry = self.names.get(node.text)
        if entry is None:
            self._unknown_name(node)
            return None
        return entry.type

    def _unknown_name(self, node: Atom) -> None:
        in_problem = self.report.file != self.domain.file
        what = "object or constant" if in_problem else "constant"
        code = "unknown-object" if in_problem else "unknown-constant"
        hint = did_you_mean(node.text, self.names)
        self.report.add(node, code, f"unknown {what} '{node.text}'{hint}")

    # ---- numeric expressions -----------------------------------------------------------

    def numeric(self, node: Node, scope: dict[str, str]) -> None:
        """A numeric expression: number, function term or arithmetic."""
        if isinstance(node, Atom):
            if not is_number(node.text):
                self.report.add(
                    node, "syntax", f"expected a number or a function term, not '{node.text}'"
                )
            return
        head = node.head()
        if head in ARITHMETIC:
            self._need(":numeric-fluents", node)
            for child in node.items[1:]:
                self.numeric(child, scope)
            return
        self.function_term(node, scope)

    def function_term(self, node: SList, scope: dict[str, str]) -> None:
        """A function application: known function, right arity and types."""
        head = node.head()
        sig = self.domain.functions.get(head)
        if sig is None:
            hint = did_you_mean(head, self.domain.functions)
            what = "a predicate, not a function" if head in self.domain.predicates else ""
            msg = f"'{head}' is {what}" if what else f"unknown function '{head}'{hint}"
            self.report.add(node, "unknown-function", msg)
            return
        self.arguments(node, sig.params, scope, "function")

    # ---- effects -----------------------------------------------------------------------

    def effect(self, node: Node, scope: dict[str, str]) -> None:
        """An action effect."""
        if not isinstance(node, SList):
            self.report.add(node, "syntax", f"expected an effect in parentheses, not '{node.text}'")
            return
        head = node.head()
        if not node.items:
            return
        if head == "and":
            for child in node.items[1:]:
                self.effect(child, scope)
        elif head == "not":
            if self._fixed(node, 1):
                self._effect_atom(node.items[1], scope)
        elif head == "forall":
            self._need(":conditional-effects", node)
            inner = self._quantified(node, scope)
            if inner is not None:
                self.effect(node.items[2], inner)
        elif head == "when":
            self._need(":conditional-effects", node)
            if self._fixed(node, 2):
                self.goal(node.items[1], scope)
                self.effect(node.items[2], scope)
        elif head in ASSIGNMENTS:
            self._assignment(node, scope)
        elif head == "probabilistic":
            self._probabilistic(node, scope)
        else:
            self._effect_atom(node, scope)

    def _effect_atom(self, node: Node, scope: dict[str, str]) -> None:
        if isinstance(node, SList) and node.items:
            self.atom(node, scope)
        else:
            self.report.add(node, "syntax", "expected a predicate application (p ?x ...)")

    def _assignment(self, node: SList, scope: dict[str, str]) -> None:
        if not self._fixed(node, 2):
            return
        target, value = node.items[1], node.items[2]
        if not isinstance(target, SList):
            self.report.add(target, "syntax", "expected a function term such as (total-cost)")
            return
        is_cost = target.head() == TOTAL_COST and node.head() == "increase"
        self._need(":action-costs" if is_cost else ":numeric-fluents", node)
        self.usage.changed_functions.append((target.head(), node))
        self.function_term(target, scope)
        self.numeric(value, scope)
        if isinstance(value, SList) and value.head() in self.domain.functions:
            self.usage.cost_functions.add(value.head())

    def _probabilistic(self, node: SList, scope: dict[str, str]) -> None:
        self._need(":probabilistic-effects", node)
        if len(node) != 3:
            self.report.add(node, "syntax", "expected (probabilistic P EFFECT) with one outcome")
            return
        self.probability(node.items[1], scope)
        self.effect(node.items[2], scope)

    def probability(self, node: Node, scope: dict[str, str]) -> None:
        """P is a number or fraction in [0, 1], or a function term (a probability fluent)."""
        if isinstance(node, Atom):
            value = _number(node.text)
            if value is None:
                self.report.add(
                    node,
                    "bad-probability",
                    f"probability must be a number, a fraction or a function term, "
                    f"not '{node.text}'",
                )
            elif not 0 <= value <= 1:
                self.report.add(
                    node, "probability-range", f"probability {node.text} is outside [0, 1]"
                )
            return
        if node.head() in ARITHMETIC or not node.items:
            self.report.add(node, "bad-probability", "probability must be a single function term")
            return
        self.function_term(node, scope)
        if node.head() in self.domain.functions:
            self.usage.probability_fluents.setdefault(node.head(), node)


def _number(text: str) -> Fraction | None:
    if not is_number(text):
        return None
    try:
        return Fraction(text)
    except (ValueError, ZeroDivisionError):
        return None
