"""Expressions and effects of the fast reading path, made with UP's expression manager.

`up_builder` builds the `Problem` UP's `PDDLReader` would build (or the same problem in the
project's own model, `lite`, which offers the same calls: `kit` names the model's classes).
This module holds the part that turns s-expressions (from `up_text`) into the model's
`FNode`s: the name tables of one read
(types, fluents, objects, resolved through dicts where UP's reader scans lists), signatures
and quantified variables, expressions resolved in the order UP's reader resolves them, and
action effects listed in the order UP's reader adds them (breadth first). It is the base of
the builder's class, which declares the names and assembles the `Problem`.
"""

from __future__ import annotations

from collections import OrderedDict, deque
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from avs_planner.pddl.up_text import (
    OBJECT,
    TRAJECTORY,
    Sexpr,
    TypedGroups,
    Unsupported,
    typed_groups,
)

if TYPE_CHECKING:  # UP's model, or the project's own (`lite`), which mirrors it
    from unified_planning.environment import Environment
    from unified_planning.model import Fluent, FNode, Object, Parameter, Type, Variable
    from unified_planning.model.effect import EffectKind

# (kind, fluent, value, condition, forall variables) of one effect, before it is added
Effect = tuple["EffectKind", "FNode", "FNode", "FNode", tuple["Variable", ...]]


class ExpressionTranslator:
    """The names of one read and the expressions over them. Names resolve through dicts
    (UP's reader scans the problem's lists). `kit` holds the model's classes (`Problem`,
    `Fluent`, `Object`, `Variable`, `InstantaneousAction`, `EffectKind` and the metrics):
    UP's, or `lite`'s, whose calls are the same."""

    def __init__(self, environment: Environment, kit: Any):
        self.env = environment
        self.kit = kit
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

    # ---- types and signatures ---------------------------------------------------------

    def _type(self, name: str | None) -> Type:
        found = self.types.get(OBJECT if name is None else name)
        if found is None:
            raise Unsupported(f"unknown type {name}")
        return found

    def _parameters(self, groups: TypedGroups) -> OrderedDict[str, Type]:
        """A signature; the model's constructors take an OrderedDict (not a dict)."""
        signature: OrderedDict[str, Type] = OrderedDict()
        for names, parent in groups:
            kind = self._type(parent)
            for name in names:
                if name in signature:
                    raise Unsupported(f"parameter {name} twice")
                signature[name] = kind
        return signature

    def _variables(self, node: Sexpr) -> dict[str, Variable]:
        if not isinstance(node, list):
            raise Unsupported("quantifier without a variable list")
        return {name: self.kit.Variable(name, kind, self.env)
                for name, kind in self._parameters(typed_groups(node, variables=True)).items()}

    # ---- expressions ------------------------------------------------------------------

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
        if head in TRAJECTORY:
            raise Unsupported("trajectory constraint")
        fluent = self.fluents.get(head)
        if fluent is not None:
            args = tuple(self._expression(a, params, variables) for a in node[1:])
            return em.FluentExp(fluent, args)
        if n == 1:
            return self._expression(head, params, variables)
        raise Unsupported(f"unknown head {head}")

    # ---- effects ----------------------------------------------------------------------

    def _effects(self, params: dict[str, Parameter], effect: list[Sexpr]) -> list[Effect]:
        """The effects in the order UP's reader adds them: breadth first through `and`,
        `when` and `forall` (a `when` inside a `when` keeps only its own condition, as in
        UP); a `when` whose condition simplifies to false is dropped."""
        em = self.em
        true = em.TRUE()
        kinds = self.kit.EffectKind
        effects: list[Effect] = []
        queue: deque[tuple[Sexpr, FNode, dict[str, Variable]]] = deque([(effect, true, {})])
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
                effects.append((kinds.ASSIGN, fluent, em.FALSE(), condition, forall))
            elif head in ("assign", "increase", "decrease"):
                if n != 3:
                    raise Unsupported(f"odd {head}")
                kind = {"assign": kinds.ASSIGN, "increase": kinds.INCREASE,
                        "decrease": kinds.DECREASE}[str(head)]
                effects.append((kind, self._expression(node[1], params, variables),
                                self._expression(node[2], params, variables),
                                condition, forall))
            elif head == "forall":
                if variables:
                    raise Unsupported("nested forall effects (UP's reader rejects them)")
                if n != 3:
                    raise Unsupported("odd forall")
                queue.append((node[2], condition, self._variables(node[1])))
            elif isinstance(head, str):
                effects.append((kinds.ASSIGN, self._expression(node, params, variables),
                                true, condition, forall))
            else:
                raise Unsupported("a list as effect head")
        return effects
