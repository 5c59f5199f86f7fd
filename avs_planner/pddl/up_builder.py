"""Build a unified-planning `Problem` from PDDL text directly, without UP's pyparsing reader.

UP's `PDDLReader` spends most of a read in pyparsing (a 365 KB IPC domain: about 11 s); the
model it then builds is cheap. This builder tokenizes with one regular expression and calls
UP's model API itself, so that the `Problem` it returns is the one `PDDLReader` would build:
the same user types (with the implicit `object` root exactly when UP adds one), objects,
fluents (predicates Boolean with default false, functions real), actions with their
parameters, preconditions and effects in UP's order (effects breadth first, as UP walks
them), explicit initial values (negative literals dropped), goals and metric (the
`total-cost` fluent turned into `MinimizeActionCosts` under the same conditions).

UP's reader stays the reference and the fallback. The builder takes only the constructs it
mirrors exactly (classical and numeric instantaneous actions with ADL conditions and
effects); anything else, and anything UP's grammar would read differently or reject (names
its grammar does not accept, sections out of its order, `either`, durative actions, derived
predicates, ...) raises `Unsupported`, and the caller reads the text with UP instead. The
equivalence is tested on every file the project reads
(`tests/avs_planner/pddl/test_pddl_fast_reader.py`).
"""

from __future__ import annotations

import re
from collections import OrderedDict, deque
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from unified_planning.environment import Environment, get_environment
from unified_planning.model import (
    Fluent,
    FNode,
    InstantaneousAction,
    Object,
    Parameter,
    Problem,
    Type,
    Variable,
)
from unified_planning.model.effect import EffectKind
from unified_planning.model.metrics import (
    MaximizeExpressionOnFinalState,
    MinimizeActionCosts,
    MinimizeExpressionOnFinalState,
    MinimizeMakespan,
)

Sexpr = str | list[Any]  # an atom (lower-case text) or a list of s-expressions

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
_DOMAIN_SECTIONS = (":requirements", ":types", ":constants", ":predicates", ":functions")
_TRAJECTORY = frozenset(("always", "sometime", "sometime-before", "sometime-after",
                         "at-most-once"))


class Unsupported(Exception):
    """The builder does not take this text (a construct it does not mirror, or text UP
    would read differently or reject); the caller reads it with UP's own reader."""


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


def build_problem(domain_text: str, problem_text: str,
                  environment: Environment | None = None) -> Problem:
    """The `Problem` UP's `PDDLReader().parse_problem_string(domain_text, problem_text)`
    builds, or `Unsupported` (or any error UP's model raises) for text left to UP."""
    for text in (domain_text, problem_text):
        if any(m.group() != "- number" for m in _NUMBER_TYPE.finditer(text.lower())):
            raise Unsupported("a function type not written '- number'")
    return _Builder(get_environment(environment)).build(tokenize(domain_text),
                                                        tokenize(problem_text))


def _define(nodes: list[Sexpr], kind: str) -> tuple[str, list[Sexpr]]:
    """The name and sections of the single `(define (KIND NAME) ...)`."""
    if len(nodes) != 1 or not isinstance(nodes[0], list):
        raise Unsupported("not one define")
    define = nodes[0]
    if len(define) < 2 or define[0] != "define" or not isinstance(define[1], list):
        raise Unsupported("not a define")
    header = define[1]
    if len(header) != 2 or header[0] != kind or not _is_name(header[1]):
        raise Unsupported(f"not a {kind} header")
    sections = define[2:]
    for section in sections:
        if not isinstance(section, list) or not section or not isinstance(section[0], str):
            raise Unsupported("a section that is not a keyword list")
    return header[1], sections


def _is_name(node: Sexpr) -> bool:
    return isinstance(node, str) and _NAME.match(node) is not None


def _typed_groups(items: list[Sexpr], variables: bool) -> list[tuple[list[str], str | None]]:
    """`a b - t c` as UP's grammar groups it: [([a, b], t), ([c], None)]; variables lose
    their `?`. Anything else (`either`, a dangling `-`, other tokens) is not taken."""
    pattern = _VARIABLE if variables else _NAME
    groups: list[tuple[list[str], str | None]] = []
    names: list[str] = []
    i = 0
    while i < len(items):
        item = items[i]
        if item == "-":
            parent = items[i + 1] if i + 1 < len(items) else None
            if not names or parent is None or not _is_name(parent):
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


def _needs_object(groups: list[tuple[list[str], str | None]]) -> bool:
    return any(parent in (None, OBJECT) for _, parent in groups)


@dataclass
class _Action:
    """An action while the problem is read: its effects wait until it is known whether
    `total-cost` becomes the action-cost metric (UP then drops each action's first
    `total-cost` effect)."""

    action: InstantaneousAction
    parameters: dict[str, Parameter]
    effects: list[tuple[EffectKind, FNode, FNode, FNode, tuple[Variable, ...]]] = field(
        default_factory=list)


class _Builder:
    """One read. Names resolve through dicts (UP's reader scans the problem's lists)."""

    def __init__(self, environment: Environment):
        self.env = environment
        self.em = environment.expression_manager
        self.tm = environment.type_manager
        em = self.em
        self.operators = {
            "and": em.And, "or": em.Or, "not": em.Not, "imply": em.Implies,
            ">=": em.GE, "<=": em.LE, ">": em.GT, "<": em.LT, "=": em.Equals,
            "+": em.Plus, "-": em.Minus, "/": em.Div, "*": em.Times,
        }
        self.types: dict[str, Type] = {}
        self.fluents: dict[str, Fluent] = {}
        self.objects: dict[str, Object] = {}

    # ---- the whole read ---------------------------------------------------------------

    def build(self, domain: list[Sexpr], problem_nodes: list[Sexpr]) -> Problem:
        domain_name, sections = _define(domain, "domain")
        parts = self._domain_parts(sections)
        problem_name, psections = _define(problem_nodes, "problem")
        pparts = self._problem_parts(psections)

        problem = Problem(domain_name, self.env,
                          initial_defaults={self.tm.BoolType(): self.em.FALSE()})
        predicates = [_signature(p) for p in parts.get(":predicates", [])]
        functions = [_signature(f) for f in _functions(parts.get(":functions"))]
        constants = _typed_groups(parts.get(":constants", []), variables=False)
        action_groups = [(a, _typed_groups(_action_parts(a)[0], variables=True))
                         for a in parts["actions"]]
        needs_object = (any(_needs_object(g) for _, g in predicates + functions)
                        or _needs_object(constants)
                        or any(_needs_object(g) for _, g in action_groups))
        self._declare_types(problem, parts.get(":types"), needs_object)

        fluent_list = [self._fluent(name, groups, self.tm.BoolType())
                       for name, groups in predicates]
        fluent_list += [self._fluent(name, groups, self.tm.RealType())
                        for name, groups in functions]
        constant_list = self._objects(constants)
        actions = [self._action(a, groups) for a, groups in action_groups]
        object_list = self._objects(_typed_groups(pparts.get(":objects", []),
                                                  variables=False))
        init = self._init(pparts[":init"])
        goal = self._expression(pparts[":goal"], None, {})

        total_cost = self.fluents.get(TOTAL_COST) if any(
            name == TOTAL_COST for name, _ in functions) else None
        metric = pparts.get(":metric")
        costs_from = self._cost_fluent(total_cost, actions, init, goal, metric)
        if costs_from is not None and TOTAL_COST in (
                set(self.types) | {a.action.name for a in actions} | set(self.objects)):
            raise Unsupported("total-cost also names something else")
        if costs_from is not None and not actions:
            raise Unsupported("action costs without actions (UP's reader fails on it)")

        for fluent in fluent_list:
            if costs_from is None or fluent is not total_cost:
                problem.add_fluent(fluent)
        for obj in constant_list:
            problem.add_object(obj)
        costs: dict[InstantaneousAction, FNode] = {}
        for action in actions:
            self._add_effects(action, costs_from, costs)
            problem.add_action(action.action)
        for obj in object_list:
            problem.add_object(obj)
        problem.name = problem_name
        for fluent_exp, value in init:
            if costs_from is None or fluent_exp is not costs_from:
                problem.set_initial_value(fluent_exp, value)
        problem.add_goal(goal)
        if metric is not None:
            problem.add_quality_metric(self._metric(metric, costs_from, costs))
        return problem

    def _domain_parts(self, sections: list[Sexpr]) -> dict[str, Any]:
        """The sections by keyword, in the order UP's grammar requires; `actions` a list."""
        parts: dict[str, Any] = {"actions": []}
        done = -1
        for section in sections:
            assert isinstance(section, list)
            key = section[0]
            if key == ":action":
                done = len(_DOMAIN_SECTIONS)
                parts["actions"].append(section)
                continue
            if key not in _DOMAIN_SECTIONS or _DOMAIN_SECTIONS.index(key) <= done:
                raise Unsupported(f"domain section {key} (or out of UP's order)")
            done = _DOMAIN_SECTIONS.index(key)
            parts[key] = section[1:]
        _requirements(parts.get(":requirements"))
        if ":types" in parts and not parts[":types"]:
            raise Unsupported("empty :types")
        if ":predicates" in parts:
            if not parts[":predicates"] or not all(isinstance(p, list)
                                                   for p in parts[":predicates"]):
                raise Unsupported("empty or odd :predicates")
        return parts

    def _problem_parts(self, sections: list[Sexpr]) -> dict[str, Any]:
        order = (":domain", ":requirements", ":objects", ":init", ":goal", ":metric")
        parts: dict[str, Any] = {}
        done = -1
        for section in sections:
            assert isinstance(section, list)
            key = section[0]
            if key not in order or order.index(key) <= done:
                raise Unsupported(f"problem section {key} (or out of UP's order)")
            done = order.index(key)
            parts[key] = section[1:]
        domain = parts.get(":domain")
        if domain is None or len(domain) != 1 or not _is_name(domain[0]):
            raise Unsupported("no (:domain NAME)")
        _requirements(parts.get(":requirements"))
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

    # ---- types, fluents, objects ------------------------------------------------------

    def _declare_types(self, problem: Problem, items: list[Sexpr] | None,
                       needs_object: bool) -> None:
        """UP's type tree: an untyped type hangs under `object` only when some predicate,
        function, constant or action parameter is untyped or of type `object`; a parent
        nobody declares is made a root; every declared type is in the problem even if
        unused (`_add_user_type` is the model's only way to add a bare type)."""
        declared: dict[str, str | None] = {}
        for names, parent in _typed_groups(items or [], variables=False):
            father = OBJECT if parent is None and needs_object else parent
            for name in names:
                if name in declared:
                    raise Unsupported(f"type {name} declared twice")
                if name == OBJECT:
                    father = None  # and for the rest of this group, as UP's reader does
                declared[name] = father
        types = self.types

        def declare(name: str, father_name: str | None, depth: int) -> None:
            if name in types:
                return
            if depth > len(declared):
                raise Unsupported("a cycle in the type hierarchy")
            father: Type | None = None
            if father_name is None:
                father = None
            elif father_name in types:
                father = types[father_name]
            elif father_name in declared:
                if father_name == name:
                    raise Unsupported(f"type {name} is its own parent")
                declare(father_name, declared[father_name], depth + 1)
                father = types[father_name]
            elif father_name == OBJECT and not needs_object:
                father = None
            else:
                father = types[father_name] = self.tm.UserType(father_name, None)
            types[name] = self.tm.UserType(name, father)
            problem._add_user_type(types[name])

        for name, father_name in declared.items():
            declare(name, father_name, 0)
        if needs_object and OBJECT not in types:
            types[OBJECT] = self.tm.UserType(OBJECT, None)

    def _type(self, name: str | None) -> Type:
        found = self.types.get(OBJECT if name is None else name)
        if found is None:
            raise Unsupported(f"unknown type {name}")
        return found

    def _parameters(self, groups: list[tuple[list[str], str | None]]
                    ) -> OrderedDict[str, Type]:
        """A signature; the model's constructors take an OrderedDict (not a dict)."""
        signature: OrderedDict[str, Type] = OrderedDict()
        for names, parent in groups:
            kind = self._type(parent)
            for name in names:
                if name in signature:
                    raise Unsupported(f"parameter {name} twice")
                signature[name] = kind
        return signature

    def _fluent(self, name: str, groups: list[tuple[list[str], str | None]],
                kind: Type) -> Fluent:
        if name in self.fluents:
            raise Unsupported(f"fluent {name} twice")
        fluent = Fluent(name, kind, self._parameters(groups), self.env)
        self.fluents[name] = fluent
        return fluent

    def _objects(self, groups: list[tuple[list[str], str | None]]) -> list[Object]:
        made = []
        for names, parent in groups:
            kind = self._type(parent)
            for name in names:
                if name in self.objects:
                    raise Unsupported(f"object {name} twice")
                obj = self.objects[name] = Object(name, kind, self.env)
                made.append(obj)
        return made

    # ---- actions ----------------------------------------------------------------------

    def _action(self, node: list[Sexpr], groups: list[tuple[list[str], str | None]]
                ) -> _Action:
        _, precondition, effect = _action_parts(node)
        action = InstantaneousAction(str(node[1]), self._parameters(groups), self.env)
        built = _Action(action, {p.name: p for p in action.parameters})
        if precondition is not None:
            action.add_precondition(self._expression(precondition, built.parameters, {}))
        if effect is not None:
            self._effects(built, effect)
        return built

    def _effects(self, built: _Action, effect: list[Sexpr]) -> None:
        """The effects in the order UP's reader adds them: breadth first through `and`,
        `when` and `forall` (a `when` inside a `when` keeps only its own condition, as in
        UP); a `when` whose condition simplifies to false is dropped."""
        em = self.em
        true = em.TRUE()
        queue: deque[tuple[Sexpr, FNode, dict[str, Variable]]] = deque([(effect, true, {})])
        params = built.parameters
        while queue:
            node, condition, variables = queue.popleft()
            if not isinstance(node, list):
                raise Unsupported("an atom as effect")
            if not node:
                continue
            head, n = node[0], len(node)
            forall = tuple(variables.values())
            if head == "and":
                queue.extend((child, condition, variables) for child in node[1:])
            elif head == "when":
                if n != 3:
                    raise Unsupported("odd when")
                when = self._expression(node[1], params, variables).simplify()
                if not when.is_false():
                    queue.append((node[2], when, variables))
            elif head == "not":
                if n != 2:
                    raise Unsupported("odd not")
                fluent = self._expression(node[1], params, variables)
                built.effects.append((EffectKind.ASSIGN, fluent, em.FALSE(), condition,
                                      forall))
            elif head in ("assign", "increase", "decrease"):
                if n != 3:
                    raise Unsupported(f"odd {head}")
                kind = {"assign": EffectKind.ASSIGN, "increase": EffectKind.INCREASE,
                        "decrease": EffectKind.DECREASE}[str(head)]
                built.effects.append((kind, self._expression(node[1], params, variables),
                                      self._expression(node[2], params, variables),
                                      condition, forall))
            elif head == "forall":
                if variables:
                    raise Unsupported("nested forall effects (UP's reader rejects them)")
                if n != 3:
                    raise Unsupported("odd forall")
                queue.append((node[2], condition, self._variables(node[1])))
            elif isinstance(head, str):
                built.effects.append((EffectKind.ASSIGN,
                                      self._expression(node, params, variables), true,
                                      condition, forall))
            else:
                raise Unsupported("a list as effect head")

    def _add_effects(self, built: _Action, costs_from: FNode | None,
                     costs: dict[InstantaneousAction, FNode]) -> None:
        """Add the effects through the model API; with action costs, the first effect on
        `total-cost` becomes the action's cost instead (as UP's reader does)."""
        action = built.action
        add = {EffectKind.ASSIGN: action.add_effect,
               EffectKind.INCREASE: action.add_increase_effect,
               EffectKind.DECREASE: action.add_decrease_effect}
        for kind, fluent, value, condition, forall in built.effects:
            if costs_from is not None and fluent is costs_from and action not in costs:
                costs[action] = value
                continue
            add[kind](fluent, value, condition, forall=forall)

    # ---- problem ----------------------------------------------------------------------

    def _init(self, items: list[Sexpr]) -> list[tuple[FNode, FNode]]:
        if len(items) == 1 and items[0][0] == "and":
            items = items[0][1:]
        values: list[tuple[FNode, FNode]] = []
        true = self.em.TRUE()
        for item in items:
            if not isinstance(item, list) or not item:
                raise Unsupported("an :init entry UP's reader does not take")
            head = item[0]
            if head == "=":
                if len(item) != 3:
                    raise Unsupported("odd (= ...) in :init")
                values.append((self._expression(item[1], None, {}),
                               self._expression(item[2], None, {})))
                continue
            if head == "at" and len(item) == 3 and (
                    not isinstance(item[1], str) or item[1].replace(".", "", 1).isdigit()):
                raise Unsupported("timed initial literal")
            if head in ("oneof", "or", "unknown"):
                raise Unsupported("contingent initial state")
            literal = self._expression(item, None, {})
            if literal.is_not():
                if not literal.arg(0).is_fluent_exp():
                    raise Unsupported("(not X) in :init with X not a fluent")
                continue  # a negative literal: the closed world says it already
            if not literal.is_fluent_exp():
                raise Unsupported("an :init entry that is not a fluent")
            values.append((literal, true))
        return values

    def _cost_fluent(self, total_cost: Fluent | None, actions: list[_Action],
                     init: list[tuple[FNode, FNode]], goal: FNode,
                     metric: list[Sexpr] | None) -> FNode | None:
        """`total-cost` as a fluent expression if it becomes `MinimizeActionCosts`: it is
        declared, only increased, unconditionally, and read nowhere, starts at 0, and
        the metric minimizes it; else None (UP's conditions)."""
        if total_cost is None:
            return None
        cost = self.em.FluentExp(total_cost)
        free = self.env.free_vars_extractor.get
        for built in actions:
            if any(cost in free(c) for c in built.action.preconditions):
                return None
            for kind, fluent, value, condition, _ in built.effects:
                if cost in free(value) or cost in free(condition):
                    return None
                if fluent is cost and (kind != EffectKind.INCREASE or not condition.is_true()):
                    return None
        start = None
        for fluent_exp, value in init:
            if fluent_exp is cost:
                start = value
        if start is None:
            return None
        if not start.is_constant():
            raise Unsupported("a total-cost start UP's reader cannot compare")
        if start.constant_value() != 0 or cost in free(goal):
            return None
        if metric is None or metric[0] != "minimize" or metric[1] == ["total-time"]:
            return None
        if self._expression(metric[1], None, {}) is not cost:
            return None
        return cost

    def _metric(self, metric: list[Sexpr], costs_from: FNode | None,
                costs: dict[InstantaneousAction, FNode]) -> Any:
        if costs_from is not None:
            return MinimizeActionCosts(costs, self.em.Int(0))
        direction, node = metric
        if direction == "minimize" and node == ["total-time"]:
            return MinimizeMakespan()
        expression = self._expression(node, None, {})
        if direction == "minimize":
            return MinimizeExpressionOnFinalState(expression)
        return MaximizeExpressionOnFinalState(expression)

    # ---- expressions ------------------------------------------------------------------

    def _variables(self, node: Sexpr) -> dict[str, Variable]:
        if not isinstance(node, list):
            raise Unsupported("quantifier without a variable list")
        return {name: Variable(name, kind, self.env)
                for name, kind in self._parameters(_typed_groups(node, variables=True)).items()}

    def _expression(self, node: Sexpr, params: dict[str, Parameter] | None,
                    variables: dict[str, Variable]) -> FNode:
        """A UP expression as UP's reader makes it: operators first, then quantifiers,
        then fluents; a one-item list is its item; atoms are variables, parameters,
        0-ary fluents, objects, then numbers (integers where whole)."""
        em = self.em
        if isinstance(node, str):
            if node[0] == "?":
                variable = variables.get(node[1:])
                if variable is not None:
                    return em.VariableExp(variable)
                parameter = None if params is None else params.get(node[1:])
                if parameter is None:
                    raise Unsupported(f"unknown variable {node}")
                return em.ParameterExp(parameter)
            fluent = self.fluents.get(node)
            if fluent is not None:
                return em.FluentExp(fluent)
            obj = self.objects.get(node)
            if obj is not None:
                return em.ObjectExp(obj)
            try:
                number = Fraction(node)
            except (ValueError, ZeroDivisionError) as exc:
                raise Unsupported(f"unknown name {node}") from exc
            if number.denominator == 1:
                return em.Int(number.numerator)
            return em.Real(number)
        if not node:
            return em.TRUE()
        head, n = node[0], len(node)
        if not isinstance(head, str):
            raise Unsupported("a list as expression head")
        if head == "-" and n == 2:
            return em.Times(-1, self._expression(node[1], params, variables))
        operator = self.operators.get(head)
        if operator is not None:
            return operator(*[self._expression(a, params, variables) for a in node[1:]])
        if head in ("exists", "forall"):
            if n != 3:
                raise Unsupported(f"odd {head}")
            bound = self._variables(node[1])
            body = self._expression(node[2], params, {**variables, **bound})
            quantifier = em.Exists if head == "exists" else em.Forall
            return quantifier(body, *bound.values())
        if head in _TRAJECTORY:
            raise Unsupported("trajectory constraint")
        fluent = self.fluents.get(head)
        if fluent is not None:
            args = tuple(self._expression(a, params, variables) for a in node[1:])
            return em.FluentExp(fluent, args)
        if n == 1:
            return self._expression(head, params, variables)
        raise Unsupported(f"unknown head {head}")


def _requirements(items: list[Sexpr] | None) -> None:
    """UP's grammar knows a fixed list; `:hierarchy` and `:contingent` make other kinds
    of problem (left to UP)."""
    if items is None:
        return
    if not items or any(not isinstance(r, str) or r not in _REQUIREMENTS for r in items):
        raise Unsupported("a requirement the builder does not take")


def _signature(node: Sexpr) -> tuple[str, list[tuple[list[str], str | None]]]:
    """`(name ?a - t ...)` of a predicate or function."""
    if not isinstance(node, list) or not node or not _is_name(node[0]):
        raise Unsupported("an odd predicate or function")
    return str(node[0]), _typed_groups(node[1:], variables=True)


def _functions(items: list[Sexpr] | None) -> list[Sexpr]:
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


def _action_parts(node: list[Sexpr]) -> tuple[list[Sexpr], Sexpr | None, Sexpr | None]:
    """Parameters, precondition and effect of `(:action NAME :parameters (..)
    [:precondition X] [:effect X])`, in that order only, as UP's grammar requires."""
    if len(node) < 4 or not _is_name(node[1]) or node[2] != ":parameters":
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

