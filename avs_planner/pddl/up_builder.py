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

`build_lite` builds the same problem in the project's own model (`lite`), which offers the
model calls the builder makes, without importing UP: `avs plan` grounds that one. What
`lite` does not mirror raises there too, and the reader then builds UP's. `lite` also
reads derived predicates (`:derived`), which UP 1.3's model lacks: a domain with them has
no UP counterpart.

The work is split in three modules: `up_text` tokenizes the text and takes its sections
apart (and defines `Unsupported`), `up_expressions` turns s-expressions into UP expressions
and effects, and this module declares types, fluents, objects and actions and assembles the
`Problem` (initial values, goal, metric).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from avs_planner.pddl import lite
from avs_planner.pddl.up_expressions import Effect, ExpressionTranslator
from avs_planner.pddl.up_text import (
    OBJECT,
    TOTAL_COST,
    Sexpr,
    TypedGroups,
    Unsupported,
    action_parts,
    check_number_types,
    define,
    domain_parts,
    function_declarations,
    needs_object,
    problem_parts,
    signature,
    tokenize,
    typed_groups,
)

if TYPE_CHECKING:
    from unified_planning.environment import Environment
    from unified_planning.model import (
        Fluent,
        FNode,
        InstantaneousAction,
        Object,
        Parameter,
        Problem,
        Type,
    )

__all__ = ["Unsupported", "build_lite", "build_problem", "tokenize"]


def build_problem(domain_text: str, problem_text: str,
                  environment: Environment | None = None) -> Problem:
    """The `Problem` UP's `PDDLReader().parse_problem_string(domain_text, problem_text)`
    builds, or `Unsupported` (or any error UP's model raises) for text left to UP."""
    from unified_planning.environment import get_environment

    for text in (domain_text, problem_text):
        check_number_types(text)
    return _Builder(get_environment(environment), _up_kit()).build(tokenize(domain_text),
                                                                   tokenize(problem_text))


def build_lite(domain_text: str, problem_text: str, names_shared: bool = False
               ) -> lite.Problem:
    """The same problem in the project's own model (`lite`), without importing UP; raises
    `Unsupported` or `lite.ModelError` (or another error) for text it leaves to UP. With
    `names_shared`, a type, predicate and action may share a name (UP's `error_used_name`
    lifted, as the reader lifts it)."""
    for text in (domain_text, problem_text):
        check_number_types(text)
    builder = _Builder(lite.environment(names_shared), lite)  # type: ignore[arg-type]
    return builder.build(tokenize(domain_text), tokenize(problem_text))  # type: ignore[return-value]


def _up_kit() -> SimpleNamespace:
    """UP's model classes the builder uses (`lite` offers the same names)."""
    from unified_planning.model import (
        Fluent,
        InstantaneousAction,
        Object,
        Problem,
        Variable,
    )
    from unified_planning.model.effect import EffectKind
    from unified_planning.model.metrics import (
        MaximizeExpressionOnFinalState,
        MinimizeActionCosts,
        MinimizeExpressionOnFinalState,
        MinimizeMakespan,
    )
    return SimpleNamespace(
        Problem=Problem, Fluent=Fluent, Object=Object, Variable=Variable,
        InstantaneousAction=InstantaneousAction, EffectKind=EffectKind,
        MinimizeActionCosts=MinimizeActionCosts, MinimizeMakespan=MinimizeMakespan,
        MinimizeExpressionOnFinalState=MinimizeExpressionOnFinalState,
        MaximizeExpressionOnFinalState=MaximizeExpressionOnFinalState)


@dataclass
class _Action:
    """An action while the problem is read: its effects wait until it is known whether
    `total-cost` becomes the action-cost metric (UP then drops each action's first
    `total-cost` effect)."""

    action: InstantaneousAction
    parameters: dict[str, Parameter]
    effects: list[Effect] = field(default_factory=list)


class _Builder(ExpressionTranslator):
    """One read: the names it declares, and the `Problem` it assembles from them."""

    # ---- the whole read ---------------------------------------------------------------

    def build(self, domain: list[Sexpr], problem_nodes: list[Sexpr]) -> Problem:
        derived = hasattr(self.kit, "Axiom")  # `lite` has derived predicates, UP 1.3 not
        domain_name, sections = define(domain, "domain")
        parts = domain_parts(sections, derived)
        problem_name, psections = define(problem_nodes, "problem")
        pparts = problem_parts(psections, derived)

        problem = self.kit.Problem(domain_name, self.env,
                                   initial_defaults={self.tm.BoolType(): self.em.FALSE()})
        predicates = [signature(p) for p in parts.get(":predicates", [])]
        functions = [signature(f) for f in function_declarations(parts.get(":functions"))]
        constants = typed_groups(parts.get(":constants", []), variables=False)
        action_groups = [(a, typed_groups(action_parts(a)[0], variables=True))
                         for a in parts["actions"]]
        object_root = (any(needs_object(g) for _, g in predicates + functions)
                       or needs_object(constants)
                       or any(needs_object(g) for _, g in action_groups))
        self._declare_types(problem, parts.get(":types"), object_root)

        fluent_list = [self._fluent(name, groups, self.tm.BoolType())
                       for name, groups in predicates]
        fluent_list += [self._fluent(name, groups, self.tm.RealType())
                        for name, groups in functions]
        constant_list = self._objects(constants)
        actions = [self._action(a, groups) for a, groups in action_groups]
        axioms = [self._axiom(node) for node in parts["derived"]]
        object_list = self._objects(typed_groups(pparts.get(":objects", []),
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
        for axiom in axioms:
            problem.add_axiom(axiom)
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

    # ---- types, fluents, objects ------------------------------------------------------

    def _declare_types(self, problem: Problem, items: list[Sexpr] | None,
                       object_root: bool) -> None:
        """UP's type tree: an untyped type hangs under `object` only when some predicate,
        function, constant or action parameter is untyped or of type `object`; a parent
        nobody declares is made a root; every declared type is in the problem even if
        unused (`_add_user_type` is the model's only way to add a bare type)."""
        declared: dict[str, str | None] = {}
        for names, parent in typed_groups(items or [], variables=False):
            father = OBJECT if parent is None and object_root else parent
            for name in names:
                if name in declared:
                    raise Unsupported(f"type {name} declared twice")
                if name == OBJECT:
                    father = None  # and for the rest of this group, as UP's reader does
                declared[name] = father
        for name, father_name in declared.items():
            self._declare_type(problem, declared, object_root, name, father_name, 0)
        types = self.types
        if object_root and OBJECT not in types:
            types[OBJECT] = self.tm.UserType(OBJECT, None)

    def _declare_type(self, problem: Problem, declared: dict[str, str | None],
                      object_root: bool, name: str, father_name: str | None,
                      depth: int) -> None:
        """Declare `name` under `father_name`, its undeclared ancestors first (a method, not
        a closure calling itself: that cycle kept the problem until the garbage collector
        ran)."""
        types = self.types
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
            self._declare_type(problem, declared, object_root, father_name,
                               declared[father_name], depth + 1)
            father = types[father_name]
        elif father_name == OBJECT and not object_root:
            father = None
        else:
            father = types[father_name] = self.tm.UserType(father_name, None)
        types[name] = self.tm.UserType(name, father)
        problem._add_user_type(types[name])

    def _fluent(self, name: str, groups: TypedGroups, kind: Type) -> Fluent:
        if name in self.fluents:
            raise Unsupported(f"fluent {name} twice")
        fluent = self.kit.Fluent(name, kind, self._parameters(groups), self.env)
        self.fluents[name] = fluent
        return fluent

    def _objects(self, groups: TypedGroups) -> list[Object]:
        made = []
        for names, parent in groups:
            kind = self._type(parent)
            for name in names:
                if name in self.objects:
                    raise Unsupported(f"object {name} twice")
                obj = self.objects[name] = self.kit.Object(name, kind, self.env)
                made.append(obj)
        return made

    # ---- actions ----------------------------------------------------------------------

    def _action(self, node: list[Sexpr], groups: TypedGroups) -> _Action:
        _, precondition, effect = action_parts(node)
        action = self.kit.InstantaneousAction(str(node[1]), self._parameters(groups),
                                              self.env)
        built = _Action(action, {p.name: p for p in action.parameters})
        if precondition is not None:
            action.add_precondition(self._expression(precondition, built.parameters, {}))
        if effect is not None:
            built.effects = self._effects(built.parameters, effect)
        return built

    def _axiom(self, node: list[Sexpr]) -> Any:
        """`(:derived (p ?x - t ...) BODY)` as the model's `Axiom` (only `lite` has them)."""
        if len(node) != 3 or not isinstance(node[1], list) or not node[1]:
            raise Unsupported("an odd :derived")
        head = node[1]
        fluent = self.fluents.get(str(head[0]))
        if fluent is None:
            raise Unsupported(f"derived predicate {head[0]} is not declared")
        axiom = self.kit.Axiom(fluent, self._parameters(typed_groups(head[1:], True)),
                               self.env)
        axiom.set_body(self._expression(node[2], {p.name: p for p in axiom.parameters}, {}))
        return axiom

    def _add_effects(self, built: _Action, costs_from: FNode | None,
                     costs: dict[InstantaneousAction, FNode]) -> None:
        """Add the effects through the model API; with action costs, the first effect on
        `total-cost` becomes the action's cost instead (as UP's reader does)."""
        action = built.action
        kinds = self.kit.EffectKind
        add = {kinds.ASSIGN: action.add_effect,
               kinds.INCREASE: action.add_increase_effect,
               kinds.DECREASE: action.add_decrease_effect}
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
                if fluent is cost and (kind != self.kit.EffectKind.INCREASE
                                       or not condition.is_true()):
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
        kit = self.kit
        if costs_from is not None:
            return kit.MinimizeActionCosts(costs, self.em.Int(0))
        direction, node = metric
        if direction == "minimize" and node == ["total-time"]:
            return kit.MinimizeMakespan()
        expression = self._expression(node, None, {})
        if direction == "minimize":
            return kit.MinimizeExpressionOnFinalState(expression)
        return kit.MaximizeExpressionOnFinalState(expression)
