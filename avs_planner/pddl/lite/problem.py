"""The problem: what a read adds through UP's calls, read back through UP's accessors; its
UP counterpart (`to_up`)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any

from avs_planner.pddl.lite.actions import InstantaneousAction
from avs_planner.pddl.lite.axioms import Axiom
from avs_planner.pddl.lite.declarations import BOOL, Fluent, Object, Type, UserType
from avs_planner.pddl.lite.kinds import ModelError
from avs_planner.pddl.lite.metrics import _Metric
from avs_planner.pddl.lite.nodes import FNode
from avs_planner.pddl.lite.shared_environment import ENVIRONMENT, Environment


class Problem:
    """Types, fluents, objects, actions, initial values, goals and metrics, added through
    UP's calls with UP's checks; `to_up()` gives the UP problem of the same text (built when
    first asked, by the reader's recipe in `counterpart`)."""

    events: tuple = ()
    processes: tuple = ()
    timed_effects: Mapping = {}

    def __init__(self, name: str | None = None, environment: Environment | None = None, *,
                 initial_defaults: Mapping[Type, FNode] | None = None):
        self.name = name
        self._env = environment or ENVIRONMENT
        self._initial_defaults = dict(initial_defaults or {})
        self._user_types: list[UserType] = []
        self._fluents: dict[str, Fluent] = {}
        self._fluents_defaults: dict[Fluent, FNode] = {}
        self._actions: dict[str, InstantaneousAction] = {}
        self._axioms: list[Axiom] = []
        self._objects: dict[str, Object] = {}
        self._type_names: dict[str, UserType] = {}
        self._initial_value: dict[FNode, FNode] = {}
        self._goals: list[FNode] = []
        self._metrics: list[_Metric] = []
        self.counterpart: Callable[[], tuple[Any, Mapping[str, Any]]] | None = None
        self._up: tuple[Any, Mapping[str, Any]] | None = None

    @property
    def environment(self) -> Environment:
        return self._env

    def to_up(self) -> tuple[Any, Mapping[str, Any]]:
        """The UP problem of the same text and its success expressions (UP nodes), built
        once, when first asked."""
        if self._up is None:
            if self.counterpart is None:
                raise ModelError(f"problem {self.name} has no unified-planning counterpart")
            self._up = self.counterpart()
        return self._up

    # ---- adding ---------------------------------------------------------------------

    def has_name(self, name: str) -> bool:
        return (name in self._actions or name in self._fluents or name in self._objects
                or name in self._type_names)

    def _check_name(self, name: str, same_kind: Mapping[str, object]) -> None:
        """UP's rule: a name used twice is an error, unless the environment lets kinds share
        names (then UP only warns, and the reader does not show that warning)."""
        if self.has_name(name) and (self._env.error_used_name or name in same_kind):
            raise ModelError(f"name {name} already defined")

    def _add_user_type(self, type_: Type) -> None:
        if not isinstance(type_, UserType):
            raise ModelError("not a user type")
        if any(t is type_ for t in self._user_types):
            return
        if self.has_name(type_.name):
            # UP refuses it, or warns in words the reader does not filter
            raise ModelError(f"the type name {type_.name} is already used")
        if type_.father is not None:
            self._add_user_type(type_.father)
        self._user_types.append(type_)
        self._type_names.setdefault(type_.name, type_)

    def add_fluent(self, fluent: Fluent, *, default_initial_value: Any = None) -> Fluent:
        self._check_name(fluent.name, self._fluents)
        self._fluents[fluent.name] = fluent
        if default_initial_value is not None:
            (self._fluents_defaults[fluent],) = self._env.expression_manager.auto_promote(
                default_initial_value)
        elif fluent.type in self._initial_defaults:
            self._fluents_defaults[fluent] = self._initial_defaults[fluent.type]
        if fluent.type.is_user_type():
            self._add_user_type(fluent.type)
        for parameter in fluent.signature:
            self._add_user_type(parameter.type)
        return fluent

    def add_object(self, obj: Object) -> Object:
        self._check_name(obj.name, self._objects)
        self._objects[obj.name] = obj
        self._add_user_type(obj.type)
        return obj

    def add_action(self, action: InstantaneousAction) -> None:
        self._check_name(action.name, self._actions)
        self._actions[action.name] = action
        for parameter in action.parameters:
            self._add_user_type(parameter.type)

    def add_actions(self, actions: Iterable[InstantaneousAction]) -> None:
        for action in actions:
            self.add_action(action)

    def add_axiom(self, axiom: Axiom) -> None:
        """A rule of a derived predicate (UP's model has none: see `axioms.py`)."""
        if self._fluents.get(axiom.name) is not axiom.head:
            raise ModelError(f"derived predicate {axiom.name} is not a fluent of the problem")
        self._axioms.append(axiom)
        for parameter in axiom.parameters:
            self._add_user_type(parameter.type)

    def set_initial_value(self, fluent: Any, value: Any) -> None:
        fluent_exp, value_exp = self._env.expression_manager.auto_promote(fluent, value)
        if not fluent_exp.is_fluent_exp():
            raise ModelError("an initial value for something that is not a fluent")
        if not fluent_exp.type.is_compatible(value_exp.type):
            raise ModelError("an initial value of an incompatible type")
        self._initial_value[fluent_exp] = value_exp

    def add_goal(self, goal: Any) -> None:
        (node,) = self._env.expression_manager.auto_promote(goal)
        if node.type is not BOOL:
            raise ModelError("a goal must be Boolean")
        if not node.is_true():
            self._goals.append(node)

    def add_quality_metric(self, metric: _Metric) -> None:
        self._metrics.append(metric)

    # ---- reading --------------------------------------------------------------------

    @property
    def user_types(self) -> list[UserType]:
        return self._user_types

    @property
    def fluents(self) -> list[Fluent]:
        return list(self._fluents.values())

    @property
    def fluents_defaults(self) -> dict[Fluent, FNode]:
        return self._fluents_defaults

    @property
    def actions(self) -> list[InstantaneousAction]:
        return list(self._actions.values())

    @property
    def axioms(self) -> list[Axiom]:
        """The derived predicates' rules, in the order read."""
        return list(self._axioms)

    @property
    def all_objects(self) -> list[Object]:
        return list(self._objects.values())

    def objects(self, type_: Type) -> Iterator[Object]:
        """The objects of `type_` and of its subtypes."""
        for obj in self._objects.values():
            if obj.type.is_subtype(type_):  # type: ignore[attr-defined]
                yield obj

    @property
    def explicit_initial_values(self) -> dict[FNode, FNode]:
        return self._initial_value

    @property
    def goals(self) -> list[FNode]:
        return self._goals

    @property
    def quality_metrics(self) -> list[_Metric]:
        return self._metrics

    def has_fluent(self, name: str) -> bool:
        return name in self._fluents

    def fluent(self, name: str) -> Fluent:
        return self._fluents[name]

    def has_object(self, name: str) -> bool:
        return name in self._objects

    def object(self, name: str) -> Object:
        return self._objects[name]

    def has_action(self, name: str) -> bool:
        return name in self._actions

    def action(self, name: str) -> InstantaneousAction:
        return self._actions[name]

    def has_type(self, name: str) -> bool:
        return name in self._type_names

    def user_type(self, name: str) -> UserType:
        return self._type_names[name]

    def get_static_fluents(self) -> set[Fluent]:
        """Fluents no effect changes and no rule derives."""
        changed = {e.fluent.fluent().name for a in self._actions.values() for e in a.effects}
        changed.update(axiom.name for axiom in self._axioms)
        return {f for f in self._fluents.values() if f.name not in changed}



def is_lite(model: object) -> bool:
    """Whether a planning model is this module's (else it is a UP problem)."""
    return isinstance(model, Problem)
