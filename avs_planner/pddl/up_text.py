"""The text side of the fast reading path (`up_builder`): tokens and sections as UP reads them.

`up_builder` builds the `Problem` UP's `PDDLReader` would build, without pyparsing. This
module holds what only looks at the text: one regular expression that tokenizes it into
lower-cased s-expressions, and the small helpers that take a `define` apart into its sections,
typed lists, predicate and function signatures and action parts, each accepting exactly what
UP's grammar accepts. Whatever that grammar would read differently or reject (names it does
not take, sections out of its order, `either`, requirements it does not know, ...) raises
`Unsupported`, and the caller reads the text with UP's own reader. Nothing here touches UP's
model: the builder (`up_builder`) and the expression translation (`up_expressions`) do.
"""

from __future__ import annotations

import re
from typing import Any

Sexpr = str | list[Any]  # an atom (lower-case text) or a list of s-expressions
# `a b - t c` grouped as UP's grammar groups it: [([a, b], t), ([c], None)]
TypedGroups = list[tuple[list[str], str | None]]

OBJECT = "object"
TOTAL_COST = "total-cost"
# UP's grammar: names are letters first, then letters, digits, `_` and `-` (pyparsing
# `Word(alphas, alphanums + "_-")`); a token that is not one of these whole is not taken
_NAME = re.compile(r"[a-z][a-z0-9_-]*\Z")
_VARIABLE = re.compile(r"\?[a-z][a-z0-9_-]*\Z")
# a token directly followed by `;` keeps it, to be refused: UP reads `a;b` as one token
# inside expressions and as `a` elsewhere
_TOKEN = re.compile(r"[()]|;[^\n]*|[^\s();]+;?")
# whitespace UP's tokens do not split at (pyparsing splits at " \t\n\r" only)
_UNUSUAL = re.compile(r"[^\S \t\n\r]")
# UP's grammar takes a function's type only as the literal text "- number"
_NUMBER_TYPE = re.compile(r"-\s+number")
_REQUIREMENTS = frozenset(
    ":strips :typing :negative-preconditions :disjunctive-preconditions :equality "
    ":existential-preconditions :universal-preconditions :quantified-preconditions "
    ":conditional-effects :fluents :numeric-fluents :adl :durative-actions "
    ":duration-inequalities :timed-initial-literals :timed-initial-effects :action-costs "
    ":method-preconditions :constraints :preferences :time :continuous-effects".split()
)
_DERIVED = frozenset((":derived-predicates",))  # what a model with derived predicates takes
_DOMAIN_SECTIONS = (":requirements", ":types", ":constants", ":predicates", ":functions")
_PROBLEM_SECTIONS = (":domain", ":requirements", ":objects", ":init", ":goal", ":metric")
TRAJECTORY = frozenset(("always", "sometime", "sometime-before", "sometime-after",
                        "at-most-once"))


class Unsupported(Exception):
    """The builder does not take this text (a construct it does not mirror, or text UP
    would read differently or reject); the caller reads it with UP's own reader."""


def check_number_types(text: str) -> None:
    """UP's grammar takes a function's type only as the literal text `- number`."""
    if any(m.group() != "- number" for m in _NUMBER_TYPE.finditer(text.lower())):
        raise Unsupported("a function type not written '- number'")


def tokenize(text: str) -> list[Sexpr]:
    """The top-level s-expressions of `text`, lower-cased as UP reads them. No positions:
    the text has passed the project's own checks (which report them) before this."""
    text = text.lower()
    if _UNUSUAL.search(text) or "#t" in text:
        raise Unsupported("unusual whitespace or continuous change")
    stack: list[list[Sexpr]] = [[]]
    for token in _TOKEN.findall(text):
        if token == "(":
            node: list[Sexpr] = []
            stack[-1].append(node)
            stack.append(node)
        elif token == ")":
            if len(stack) == 1:
                raise Unsupported("unbalanced parentheses")
            stack.pop()
        elif token[0] != ";":
            if token[-1] == ";":
                raise Unsupported("';' inside a token")
            stack[-1].append(token)
    if len(stack) != 1:
        raise Unsupported("unbalanced parentheses")
    return stack[0]


def define(nodes: list[Sexpr], kind: str) -> tuple[str, list[Sexpr]]:
    """The name and sections of the single `(define (KIND NAME) ...)`."""
    if len(nodes) != 1 or not isinstance(nodes[0], list):
        raise Unsupported("not one define")
    whole = nodes[0]
    if len(whole) < 2 or whole[0] != "define" or not isinstance(whole[1], list):
        raise Unsupported("not a define")
    header = whole[1]
    if len(header) != 2 or header[0] != kind or not is_name(header[1]):
        raise Unsupported(f"not a {kind} header")
    sections = whole[2:]
    for section in sections:
        if not isinstance(section, list) or not section or not isinstance(section[0], str):
            raise Unsupported("a section that is not a keyword list")
    return header[1], sections


def is_name(node: Sexpr) -> bool:
    return isinstance(node, str) and _NAME.match(node) is not None


def typed_groups(items: list[Sexpr], variables: bool) -> TypedGroups:
    """`a b - t c` as UP's grammar groups it: [([a, b], t), ([c], None)]; variables lose
    their `?`. Anything else (`either`, a dangling `-`, other tokens) is not taken."""
    pattern = _VARIABLE if variables else _NAME
    groups: TypedGroups = []
    names: list[str] = []
    i = 0
    while i < len(items):
        item = items[i]
        if item == "-":
            parent = items[i + 1] if i + 1 < len(items) else None
            if not names or parent is None or not is_name(parent):
                raise Unsupported("a typed list UP's grammar does not take")
            groups.append((names, str(parent)))
            names = []
            i += 2
            continue
        if not isinstance(item, str) or pattern.match(item) is None:
            raise Unsupported("a typed list UP's grammar does not take")
        names.append(item[1:] if variables else item)
        i += 1
    if names:
        groups.append((names, None))
    return groups


def needs_object(groups: TypedGroups) -> bool:
    """Whether some item of `groups` is untyped or of type `object`."""
    return any(parent in (None, OBJECT) for _, parent in groups)


def domain_parts(sections: list[Sexpr], derived: bool = False) -> dict[str, Any]:
    """The sections by keyword, in the order UP's grammar requires; `actions` a list. With
    `derived` (a model that has derived predicates, `lite`), `:derived` rules too, among the
    actions, in `derived` (UP's grammar has none: the builder of UP's model leaves them)."""
    parts: dict[str, Any] = {"actions": [], "derived": []}
    done = -1
    for section in sections:
        assert isinstance(section, list)
        key = section[0]
        if key == ":action" or (key == ":derived" and derived):
            done = len(_DOMAIN_SECTIONS)
            parts["actions" if key == ":action" else "derived"].append(section)
            continue
        if key not in _DOMAIN_SECTIONS or _DOMAIN_SECTIONS.index(key) <= done:
            raise Unsupported(f"domain section {key} (or out of UP's order)")
        done = _DOMAIN_SECTIONS.index(key)
        parts[key] = section[1:]
    check_requirements(parts.get(":requirements"), _DERIVED if derived else frozenset())
    if ":types" in parts and not parts[":types"]:
        raise Unsupported("empty :types")
    if ":predicates" in parts:
        if not parts[":predicates"] or not all(isinstance(p, list)
                                               for p in parts[":predicates"]):
            raise Unsupported("empty or odd :predicates")
    return parts


def problem_parts(sections: list[Sexpr], derived: bool = False) -> dict[str, Any]:
    """The sections by keyword, in the order UP's grammar requires; `:goal` unwrapped."""
    parts: dict[str, Any] = {}
    done = -1
    for section in sections:
        assert isinstance(section, list)
        key = section[0]
        if key not in _PROBLEM_SECTIONS or _PROBLEM_SECTIONS.index(key) <= done:
            raise Unsupported(f"problem section {key} (or out of UP's order)")
        done = _PROBLEM_SECTIONS.index(key)
        parts[key] = section[1:]
    domain = parts.get(":domain")
    if domain is None or len(domain) != 1 or not is_name(domain[0]):
        raise Unsupported("no (:domain NAME)")
    check_requirements(parts.get(":requirements"), _DERIVED if derived else frozenset())
    init = parts.get(":init")
    if init is None or not all(isinstance(i, list) and i for i in init):
        raise Unsupported("no :init, or one UP's grammar does not take")
    goal = parts.get(":goal")
    if goal is None or len(goal) != 1 or not isinstance(goal[0], list):
        raise Unsupported("no goal (UP's reader fails), or an odd one")
    parts[":goal"] = goal[0]
    metric = parts.get(":metric")
    if metric is not None:
        if (len(metric) != 2 or metric[0] not in ("minimize", "maximize")
                or not isinstance(metric[1], list)):
            raise Unsupported("a metric the builder does not take")
    return parts


def check_requirements(items: list[Sexpr] | None, extra: frozenset[str] = frozenset()
                       ) -> None:
    """UP's grammar knows a fixed list (plus `extra`, flags the model being built takes);
    `:hierarchy` and `:contingent` make other kinds of problem (left to UP)."""
    if items is None:
        return
    known = _REQUIREMENTS | extra
    if not items or any(not isinstance(r, str) or r not in known for r in items):
        raise Unsupported("a requirement the builder does not take")


def signature(node: Sexpr) -> tuple[str, TypedGroups]:
    """`(name ?a - t ...)` of a predicate or function."""
    if not isinstance(node, list) or not node or not is_name(node[0]):
        raise Unsupported("an odd predicate or function")
    return str(node[0]), typed_groups(node[1:], variables=True)


def function_declarations(items: list[Sexpr] | None) -> list[Sexpr]:
    """The function declarations of `:functions`, each optionally followed by
    `- number` (UP's grammar takes no other function type)."""
    if items is None:
        return []
    if not items:
        raise Unsupported("empty :functions")
    found: list[Sexpr] = []
    i = 0
    while i < len(items):
        item = items[i]
        if not isinstance(item, list):
            raise Unsupported("an odd :functions entry")
        found.append(item)
        i += 1
        if i < len(items) and items[i] == "-":
            if i + 1 >= len(items) or items[i + 1] != "number":
                raise Unsupported("a function type other than number")
            i += 2
    return found


def action_parts(node: list[Sexpr]) -> tuple[list[Sexpr], Sexpr | None, Sexpr | None]:
    """Parameters, precondition and effect of `(:action NAME :parameters (..)
    [:precondition X] [:effect X])`, in that order only, as UP's grammar requires."""
    if len(node) < 4 or not is_name(node[1]) or node[2] != ":parameters":
        raise Unsupported("an action UP's grammar does not take")
    parameters = node[3]
    if not isinstance(parameters, list):
        raise Unsupported("an action UP's grammar does not take")
    rest = node[4:]
    found: dict[str, Sexpr] = {}
    for key in (":precondition", ":effect"):
        if rest and rest[0] == key:
            if len(rest) < 2 or not isinstance(rest[1], list):
                raise Unsupported(f"{key} that is not a list")
            found[key] = rest[1]
            rest = rest[2:]
    if rest:
        raise Unsupported("an action part the builder does not take (e.g. :observe)")
    return parameters, found.get(":precondition"), found.get(":effect")
