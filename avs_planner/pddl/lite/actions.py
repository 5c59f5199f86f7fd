"""Actions and their effects, added with UP's checks."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from avs_planner.pddl.lite.declarations import BOOL, Parameter, Type, Variable, _numeric
from avs_planner.pddl.lite.kinds import EffectKind, ModelError
from avs_planner.pddl.lite.nodes import FNode, free_fluents, free_variables
from avs_planner.pddl.lite.shared_environment import ENVIRONMENT

if TYPE_CHECKING:
    from avs_planner.pddl.lite.shared_environment import Environment


class Effect:
    """One effect as UP's: the `forall` variables it uses, in the given order."""

    __slots__ = ("fluent", "value", "condition", "kind", "forall")

    def __init__(self, fluent: FNode, value: FNode, condition: FNode,
                 kind: EffectKind = EffectKind.ASSIGN, forall: Iterable[Variable] = ()):
        if free_fluents(fluent) - {fluent}:
            raise ModelError(f"the fluent {fluent} has fluents among its arguments")
        free = free_variables(fluent) | free_variables(value) | free_variables(condition)
        used: list[Variable] = []
        for variable in forall:
            if variable in free and variable not in used:
                used.append(variable)
        if free.difference(used):
            raise ModelError("unbound variables in an effect")
        self.fluent = fluent
        self.value = value
        self.condition = condition
        self.kind = kind
        self.forall = tuple(used)

    def is_forall(self) -> bool:
        return bool(self.forall)

    def is_conditional(self) -> bool:
        return not self.condition.is_true()

    def is_assignment(self) -> bool:
        return self.kind is EffectKind.ASSIGN

    def is_increase(self) -> bool:
        return self.kind is EffectKind.INCREASE

    def is_decrease(self) -> bool:
        return self.kind is EffectKind.DECREASE

    @property
    def environment(self) -> Environment:
        return ENVIRONMENT

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Effect) and other.fluent is self.fluent
                and other.value is self.value and other.condition is self.condition
                and other.kind is self.kind and set(other.forall) == set(self.forall))

    def __hash__(self) -> int:
        return (hash(self.fluent) + hash(self.value) + hash(self.condition) + hash(self.kind)
                + sum(map(hash, self.forall)))

    def __repr__(self) -> str:
        parts = []
        if self.forall:
            parts.append(f"forall {', '.join(str(v) for v in self.forall)}")
        if self.is_conditional():
            parts.append(f"if {self.condition} then")
        parts.append(str(self.fluent))
        parts.append({EffectKind.ASSIGN: ":=", EffectKind.INCREASE: "+=",
                      EffectKind.DECREASE: "-="}[self.kind])
        parts.append(str(self.value))
        return " ".join(parts)


class InstantaneousAction:
    """An action: parameters, preconditions and effects, added as UP's model adds them."""

    simulated_effect = None

    def __init__(self, _name: str, _parameters: OrderedDict[str, Type] | None = None,
                 _env: Environment | None = None):
        self.name = _name
        self._parameters = OrderedDict((n, Parameter(n, t)) for n, t in
                                       (_parameters or {}).items())
        self.preconditions: list[FNode] = []
        self.effects: list[Effect] = []
        self._assigned: dict[FNode, FNode] = {}
        self._changed: set[FNode] = set()

    @property
    def environment(self) -> Environment:
        return ENVIRONMENT

    @property
    def parameters(self) -> list[Parameter]:
        return list(self._parameters.values())

    def parameter(self, name: str) -> Parameter:
        return self._parameters[name]

    def is_conditional(self) -> bool:
        return any(e.is_conditional() for e in self.effects)

    def add_precondition(self, precondition: Any) -> None:
        (node,) = ENVIRONMENT.expression_manager.auto_promote(precondition)
        if node.type is not BOOL:
            raise ModelError("a precondition must be Boolean")
        if node.is_true():
            return
        if free_variables(node):
            raise ModelError(f"the precondition {node} has unbound variables")
        if node not in self.preconditions:
            self.preconditions.append(node)

    def add_effect(self, fluent: Any, value: Any, condition: Any = True,
                   forall: Iterable[Variable] = ()) -> None:
        self._add(EffectKind.ASSIGN, fluent, value, condition, forall)

    def add_increase_effect(self, fluent: Any, value: Any, condition: Any = True,
                            forall: Iterable[Variable] = ()) -> None:
        self._add(EffectKind.INCREASE, fluent, value, condition, forall)

    def add_decrease_effect(self, fluent: Any, value: Any, condition: Any = True,
                            forall: Iterable[Variable] = ()) -> None:
        self._add(EffectKind.DECREASE, fluent, value, condition, forall)

    def _add(self, kind: EffectKind, fluent: Any, value: Any, condition: Any,
             forall: Iterable[Variable]) -> None:
        fluent_exp, value_exp, condition_exp = ENVIRONMENT.expression_manager.auto_promote(
            fluent, value, condition)
        if not fluent_exp.is_fluent_exp():
            raise ModelError("an effect on something that is not a fluent")
        if condition_exp.type is not BOOL:
            raise ModelError("an effect condition must be Boolean")
        if not fluent_exp.type.is_compatible(value_exp.type):
            raise ModelError("an effect value of an incompatible type")
        if kind is not EffectKind.ASSIGN and not _numeric(fluent_exp.type):
            raise ModelError("increase or decrease of a non-numeric fluent")
        effect = Effect(fluent_exp, value_exp, condition_exp, kind, forall)
        self._check_conflicts(effect)
        self.effects.append(effect)

    def _check_conflicts(self, effect: Effect) -> None:
        """UP's `check_conflicting_effects` for an action: unconditional numeric effects on
        one fluent must agree (an assignment twice, or an assignment and a change)."""
        fluent = effect.fluent
        if effect.is_conditional() or fluent.type is BOOL:
            return
        if effect.is_assignment():
            if fluent in self._changed:
                raise ModelError(f"the effect {effect} conflicts with an increase/decrease")
            assigned = self._assigned.get(fluent)
            if assigned is None:
                self._assigned[fluent] = effect.value
            elif assigned is not effect.value and not (
                    assigned.is_constant() and effect.value.is_constant()
                    and assigned.constant_value() == effect.value.constant_value()):
                raise ModelError(f"the effect {effect} conflicts with another assignment")
            return
        if fluent in self._assigned:
            raise ModelError(f"the effect {effect} conflicts with an assignment")
        self._changed.add(fluent)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, InstantaneousAction) and other.name == self.name
                and other._parameters == self._parameters
                and set(other.preconditions) == set(self.preconditions)
                and set(other.effects) == set(self.effects))

    def __hash__(self) -> int:
        return (hash(self.name) + sum(map(hash, self._parameters.items()))
                + sum(map(hash, self.preconditions)) + sum(map(hash, self.effects)))

    def __repr__(self) -> str:
        lines = [f"action {self.name}"]
        if self._parameters:
            lines[0] += "(" + ", ".join(map(str, self.parameters)) + ")"
        lines[0] += " {"
        lines.append("    preconditions = [")
        lines += [f"      {c}" for c in self.preconditions]
        lines.append("    ]")
        lines.append("    effects = [")
        lines += [f"      {e}" for e in self.effects]
        lines.append("    ]")
        lines.append("  }")
        return "\n".join(lines)
