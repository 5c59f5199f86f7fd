"""The declarations of a PDDL domain and problem, with source positions, for the linter.

Reading is forgiving: a malformed part becomes a Diagnostic and the rest is still read,
so one run of `avs domain check` reports as much as it can.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

from avs_planner.pddl.diagnostics import Diagnostic, Severity
from avs_planner.pddl.sexpr import Atom, Node, SList

OBJECT = "object"
NUMBER = "number"
_NAME = re.compile(r"[a-z][a-z0-9_-]*")


def check_name(atom: Atom, report: Report, variable: bool = False) -> None:
    """PDDL names start with a letter and continue with letters, digits, '-' and '_';
    variables are such a name after '?'."""
    text = atom.text[1:] if variable and atom.text.startswith("?") else atom.text
    if variable and not atom.text.startswith("?"):
        report.add(atom, "syntax", f"expected a variable (?x), not '{atom.text}'")
    elif not _NAME.fullmatch(text):
        what = "variable" if variable else "name"
        report.add(
            atom,
            "bad-name",
            f"'{atom.text}' is not a valid {what} (a letter, then letters, digits, '-' or '_')",
        )


@dataclass
class Report:
    """Collects diagnostics for one file."""

    file: str
    items: list[Diagnostic] = field(default_factory=list)

    def add(self, node: Node, code: str, message: str, warning: bool = False) -> None:
        severity = Severity.WARNING if warning else Severity.ERROR
        self.items.append(Diagnostic(self.file, node.line, node.column, severity, code, message))


@dataclass(frozen=True)
class Typed:
    """A name with its declared type, e.g. `?r - room` or `kitchen - category`."""

    atom: Atom
    type: str
    type_atom: Atom | None = None

    @property
    def name(self) -> str:
        return self.atom.text

    @property
    def type_node(self) -> Atom:
        """Where the type is written (the name itself when the type is implicit)."""
        return self.type_atom or self.atom


@dataclass
class Signature:
    """A predicate or function declaration."""

    atom: Atom
    params: list[Typed]

    @property
    def name(self) -> str:
        return self.atom.text


@dataclass
class Action:
    """An action schema: parameters, precondition and effect nodes (None when absent)."""

    atom: Atom
    params: list[Typed]
    precondition: Node | None = None
    effect: Node | None = None


@dataclass
class DerivedRule:
    """A `(:derived (p ?x - t ...) BODY)` rule: the head's predicate and variables, and the
    body (a goal description over the head's variables; None when missing)."""

    node: SList
    atom: Atom  # the predicate's name in the head
    params: list[Typed]
    body: Node | None = None


@dataclass
class Domain:
    """Everything declared in a domain file."""

    file: str
    name: Atom | None = None
    requirements: list[Atom] = field(default_factory=list)
    requirements_node: SList | None = None
    types: dict[str, str | None] = field(default_factory=lambda: {OBJECT: None})
    type_atoms: dict[str, Atom] = field(default_factory=dict)
    constants: dict[str, Typed] = field(default_factory=dict)
    predicates: dict[str, Signature] = field(default_factory=dict)
    functions: dict[str, Signature] = field(default_factory=dict)
    actions: dict[str, Action] = field(default_factory=dict)
    derived: list[DerivedRule] = field(default_factory=list)  # in the order written
    uses_typing: Node | None = None
    # Text edits (start, end, replacement) that make the domain readable by unified-planning
    repairs: list[tuple[int, int, str]] = field(default_factory=list)

    @property
    def derived_names(self) -> frozenset[str]:
        """The predicates some `:derived` rule defines (its truth follows from the rules)."""
        return frozenset(rule.atom.text for rule in self.derived
                         if rule.atom.text in self.predicates)

    def common_supertype(self, names: list[str]) -> str:
        """The most specific type every one of `names` descends from."""
        current: str | None = names[0]
        while current is not None:
            if all(self.is_subtype(name, current) for name in names):
                return current
            current = self.types.get(current, OBJECT if current != OBJECT else None)
        return OBJECT

    def is_subtype(self, sub: str, sup: str) -> bool:
        """True when `sub` equals `sup` or descends from it (everything is an `object`)."""
        seen: set[str] = set()
        current: str | None = sub
        while current is not None and current not in seen:
            if current == sup:
                return True
            seen.add(current)
            current = self.types.get(current, OBJECT if current != OBJECT else None)
        return sup == OBJECT


@dataclass
class Problem:
    """Everything declared in a problem file."""

    file: str
    name: Atom | None = None
    domain_ref: Atom | None = None
    objects: dict[str, Typed] = field(default_factory=dict)
    init_node: SList | None = None
    init: list[Node] = field(default_factory=list)
    goal: Node | None = None
    goal_node: SList | None = None
    metric: SList | None = None


def find_define(nodes: list[Node], kind: str, report: Report) -> SList | None:
    """The `(define (KIND name) ...)` form, or None with a diagnostic."""
    for node in nodes:
        if isinstance(node, SList) and node.head() == "define":
            header = node.items[1] if len(node) > 1 else None
            if isinstance(header, SList) and header.head() == kind and len(header) == 2:
                for extra in nodes[nodes.index(node) + 1 :]:
                    report.add(extra, "syntax", "unexpected text after the (define ...) form")
                return node
            report.add(header or node, "syntax", f"expected ({kind} NAME) after define")
            return None
        report.add(node, "syntax", f"expected (define ({kind} NAME) ...)")
        return None
    report.add(Atom("", 1, 1, 0), "syntax", f"empty file: expected (define ({kind} NAME) ...)")
    return None


Either = Callable[[SList], str]


def typed_list(
    items: list[Node],
    report: Report,
    default: str = OBJECT,
    variables: bool = True,
    either: Either | None = None,
) -> list[Typed]:
    """Parse `a b - t c` into Typed entries; stray lists are reported, and so is
    `(either ...)` unless `either` turns it into one type."""
    result: list[Typed] = []
    pending: list[Atom] = []
    i = 0
    while i < len(items):
        item = items[i]
        if isinstance(item, Atom) and item.text == "-":
            type_name = _type_after_dash(items, i, report, either)
            type_atom = items[i + 1] if i + 1 < len(items) else None
            type_atom = type_atom if isinstance(type_atom, Atom) else None
            result += [Typed(a, type_name, type_atom) for a in pending]
            pending = []
            i += 2
            continue
        if isinstance(item, SList):
            report.add(item, "syntax", "expected a name here, not a parenthesised list")
        else:
            check_name(item, report, variables)
            pending.append(item)
        i += 1
    return result + [Typed(a, default) for a in pending]


def _type_after_dash(items: list[Node], i: int, report: Report, either: Either | None) -> str:
    if i + 1 >= len(items):
        report.add(items[i], "syntax", "'-' must be followed by a type name")
        return OBJECT
    node = items[i + 1]
    if isinstance(node, SList):
        if node.head() == "either" and either is not None:
            return either(node)
        if node.head() == "either":
            report.add(
                node,
                "unsupported-either",
                "(either ...) types are not supported; declare a common supertype instead",
            )
        else:
            report.add(node, "syntax", "expected a type name after '-'")
        return OBJECT
    check_name(node, report)
    return node.text


DOMAIN_ORDER = [":requirements", ":types", ":constants", ":predicates", ":functions", ":action"]
# Sections written among the actions, in any order with them (PDDL 2.2's structure-defs)
_LIKE_ACTIONS = (":durative-action", ":derived")
PROBLEM_ORDER = [":domain", ":requirements", ":objects", ":init", ":goal", ":metric"]


def check_order(sections: list[Node], order: list[str], report: Report) -> None:
    """unified-planning reads sections only in the standard order, each at most once."""
    latest: tuple[int, str] = (-1, "")
    seen: set[str] = set()
    for section in sections:
        if not isinstance(section, SList):
            continue
        head = ":action" if section.head() in _LIKE_ACTIONS else section.head()
        if head not in order:
            continue
        rank = order.index(head)
        if head in seen and head != ":action":
            report.add(section, "duplicate", f"section '{head}' appears twice")
        elif rank < latest[0]:
            report.add(section, "syntax", f"section '{head}' must come before '{latest[1]}'")
        seen.add(head)
        if rank > latest[0]:
            latest = (rank, head)


def _start_define(define: SList, order: list[str], report: Report) -> Atom | None:
    """Check the section order of a `(define ...)` form and return its declared name."""
    check_order(define.items[2:], order, report)
    header = define.items[1]
    if isinstance(header, SList) and isinstance(header.items[1], Atom):
        return header.items[1]
    return None


def read_domain(define: SList, report: Report) -> Domain:
    """Collect a domain's declarations from its `(define ...)` form."""
    domain = Domain(report.file)
    domain.name = _start_define(define, DOMAIN_ORDER, report) or domain.name
    for section in define.items[2:]:
        if not isinstance(section, SList) or not section.head().startswith(":"):
            report.add(section, "syntax", "expected a section such as (:predicates ...)")
            continue
        reader = _DOMAIN_SECTIONS.get(section.head())
        if reader is None:
            report.add(section, "unknown-section", f"unknown domain section '{section.head()}'")
        else:
            reader(domain, section, report)
    return domain


def _requirements(domain: Domain, section: SList, report: Report) -> None:
    domain.requirements_node = section
    for item in section.items[1:]:
        if isinstance(item, Atom):
            domain.requirements.append(item)
        else:
            report.add(item, "syntax", "expected a requirement flag such as :typing")


def _types(domain: Domain, section: SList, report: Report) -> None:
    domain.uses_typing = domain.uses_typing or section
    entries = typed_list(section.items[1:], report, variables=False)
    again: list[Typed] = []
    for entry in entries:
        if entry.name == OBJECT:
            continue
        if entry.name in domain.type_atoms:
            again.append(entry)
            continue
        domain.types[entry.name] = entry.type
        domain.type_atoms[entry.name] = entry.atom
    for _name, parent in list(domain.types.items()):
        if parent is not None and parent not in domain.types:
            domain.types[parent] = OBJECT  # an undeclared parent is implicitly a type
    kept = {id(e.atom): e for e in entries}
    for entry in again:
        _declared_again(domain, entry, kept, report)
    _blank_emptied_groups(domain, section, entries, kept)
    _check_cycles(domain, report)


def _declared_again(domain: Domain, entry: Typed, kept: dict[int, Typed], report: Report) -> None:
    """A type declared twice (IPC storage: `area - object` and `area - surface`), read as
    Fast Downward does when one parent descends from the other: under the more specific."""
    first = domain.type_atoms[entry.name]
    old = domain.types[entry.name] or OBJECT
    if domain.is_subtype(old, entry.type) or domain.is_subtype(entry.type, old):
        keep_new = old != entry.type and domain.is_subtype(entry.type, old)
        dropped = first if keep_new else entry.atom
        if keep_new:
            domain.types[entry.name] = entry.type
            domain.type_atoms[entry.name] = entry.atom
        kept.pop(id(dropped), None)
        domain.repairs.append((dropped.offset, dropped.end, ""))
        report.add(dropped, "duplicate-type",
                   f"type '{entry.name}' is declared twice; read as '{entry.name} - "
                   f"{domain.types[entry.name]}'", warning=True)
        return
    report.add(entry.atom, "duplicate", f"type '{entry.name}' is declared twice, under "
               f"'{old}' and '{entry.type}'")


def _blank_emptied_groups(
    domain: Domain, section: SList, entries: list[Typed], kept: dict[int, Typed]
) -> None:
    """Blank `- parent` where every name before it was dropped (UP wants a name there)."""
    items = section.items
    for i, item in enumerate(items[:-1]):
        if not (isinstance(item, Atom) and item.text == "-"):
            continue
        group = [e for e in entries if e.type_atom is items[i + 1]]
        if group and not any(id(e.atom) in kept for e in group):
            domain.repairs.append((item.offset, items[i + 1].end, ""))


def _check_cycles(domain: Domain, report: Report) -> None:
    for name, atom in domain.type_atoms.items():
        seen: set[str] = set()
        current: str | None = name
        while current is not None and current not in seen:
            seen.add(current)
            current = domain.types.get(current)
        if current is not None:
            report.add(atom, "type-cycle", f"type '{name}' is (indirectly) its own subtype")


def _constants(domain: Domain, section: SList, report: Report) -> None:
    _typed_into(domain.constants, section, report, "constant")


def _typed_into(table: dict[str, Typed], section: SList, report: Report, what: str) -> None:
    for entry in typed_list(section.items[1:], report, variables=False):
        if entry.name in table:
            report.add(entry.atom, "duplicate", f"{what} '{entry.name}' is declared twice")
        else:
            table[entry.name] = entry


def _signatures(
    section: SList, report: Report, functions: bool, either: Either | None = None
) -> list[Signature]:
    """Predicate or function signatures; function lists may carry `- number` result types."""
    result = []
    items = section.items[1:]
    i = 0
    while i < len(items):
        item = items[i]
        if isinstance(item, SList) and item.items and isinstance(item.items[0], Atom):
            check_name(item.items[0], report)
            params = typed_list(item.items[1:], report, either=either)
            result.append(Signature(item.items[0], params))
        elif functions and isinstance(item, Atom) and item.text == "-":
            after = items[i + 1] if i + 1 < len(items) else item
            if not isinstance(after, Atom) or after.text not in (NUMBER, "int", "float"):
                report.add(after, "syntax", "a function's type must be 'number'")
            i += 2
            continue
        else:
            report.add(item, "syntax", "expected (NAME ?param - type ...)")
        i += 1
    return result


def _predicates(domain: Domain, section: SList, report: Report) -> None:
    sigs = _signatures(section, report, False, _either(domain, report))
    _signatures_into(domain.predicates, sigs, report, "predicate")


def _functions(domain: Domain, section: SList, report: Report) -> None:
    sigs = _signatures(section, report, True, _either(domain, report))
    _signatures_into(domain.functions, sigs, report, "function")


def _either(domain: Domain, report: Report) -> Either:
    """`(either a b)` in a predicate or function argument, read as the types' most specific
    common supertype (the argument's type only checks what may fill it)."""

    def read(node: SList) -> str:
        names = [a.text for a in node.items[1:] if isinstance(a, Atom)]
        common = domain.common_supertype(names) if names else OBJECT
        if len(common) > node.end - node.offset:  # the repair keeps every offset
            common = OBJECT
        domain.repairs.append((node.offset, node.end, common))
        report.add(node, "either-type", f"(either {' '.join(names)}) read as its common "
                   f"supertype '{common}'", warning=True)
        return common

    return read


def _signatures_into(
    table: dict[str, Signature], sigs: list[Signature], report: Report, what: str
) -> None:
    for sig in sigs:
        if sig.name in table:
            report.add(sig.atom, "duplicate", f"{what} '{sig.name}' is declared twice")
        else:
            table[sig.name] = sig


def _action(domain: Domain, section: SList, report: Report) -> None:
    if len(section) < 2 or not isinstance(section.items[1], Atom):
        report.add(section, "syntax", "expected (:action NAME :parameters (...) ...)")
        return
    action = Action(section.items[1], [])
    check_name(action.atom, report)
    items = section.items[2:]
    for i in range(0, len(items), 2):
        key = items[i]
        value = items[i + 1] if i + 1 < len(items) else None
        if not isinstance(key, Atom) or value is None:
            report.add(key, "syntax", "expected :parameters, :precondition or :effect and a value")
            break
        _action_part(action, key, value, report)
    if action.atom.text in domain.actions:
        report.add(action.atom, "duplicate", f"action '{action.atom.text}' is declared twice")
    domain.actions[action.atom.text] = action


def _action_part(action: Action, key: Atom, value: Node, report: Report) -> None:
    if key.text == ":parameters":
        if isinstance(value, SList):
            action.params = typed_list(value.items, report)
        else:
            report.add(value, "syntax", "expected a parameter list (?x - type ...)")
    elif key.text == ":precondition":
        action.precondition = value
    elif key.text == ":effect":
        action.effect = value
    else:
        report.add(key, "syntax", f"unknown action keyword '{key.text}'")


def _derived(domain: Domain, section: SList, report: Report) -> None:
    """`(:derived (p ?x - t ...) BODY)`; what the head and body name is checked later."""
    head = section.items[1] if len(section) > 1 else None
    if (len(section) != 3 or not isinstance(head, SList) or not head.items
            or not isinstance(head.items[0], Atom)):
        report.add(section, "syntax", "expected (:derived (PREDICATE ?x - type ...) FORMULA)")
        return
    name = head.items[0]
    check_name(name, report)
    domain.derived.append(DerivedRule(section, name, typed_list(head.items[1:], report),
                                      section.items[2]))


def _unsupported(domain: Domain, section: SList, report: Report) -> None:
    report.add(section, "unsupported", f"'{section.head()}' is not supported by avs-planner")


_DOMAIN_SECTIONS = {
    ":requirements": _requirements,
    ":types": _types,
    ":constants": _constants,
    ":predicates": _predicates,
    ":functions": _functions,
    ":action": _action,
    ":durative-action": _unsupported,
    ":derived": _derived,
    ":constraints": _unsupported,
}


def read_problem(define: SList, report: Report) -> Problem:
    """Collect a problem's declarations from its `(define ...)` form."""
    problem = Problem(report.file)
    problem.name = _start_define(define, PROBLEM_ORDER, report) or problem.name
    for section in define.items[2:]:
        if not isinstance(section, SList) or not section.head().startswith(":"):
            report.add(section, "syntax", "expected a section such as (:init ...)")
            continue
        _problem_section(problem, section, report)
    for part, what in (
        (problem.domain_ref, "(:domain NAME)"),
        (problem.init_node, "(:init ...)"),
        (problem.goal_node, "(:goal ...)"),
    ):
        if part is None:
            report.add(define, "syntax", f"the problem has no {what} section")
    return problem


def _problem_section(problem: Problem, section: SList, report: Report) -> None:
    head = section.head()
    if head == ":domain" and len(section) == 2 and isinstance(section.items[1], Atom):
        problem.domain_ref = section.items[1]
    elif head == ":objects":
        _typed_into(problem.objects, section, report, "object")
    elif head == ":init":
        problem.init_node, problem.init = section, section.items[1:]
    elif head == ":goal" and len(section) == 2:
        problem.goal_node, problem.goal = section, section.items[1]
    elif head == ":metric":
        problem.metric = section
    elif head == ":requirements":
        return
    else:
        report.add(section, "syntax", f"unknown or malformed problem section '{head}'")
