"""Derived predicates' rules (PDDL 2.2 `:derived`), which UP 1.3's model does not have.

A rule `(:derived (p ?x - t ...) BODY)` is an `Axiom`: the head's predicate (a Boolean
fluent), its parameters and the body over them. The planner (`avs_planner.cp.axioms`)
compiles and stratifies the rules; a problem with rules has no unified-planning counterpart.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

from avs_planner.pddl.lite.declarations import BOOL, Fluent, Parameter, Type
from avs_planner.pddl.lite.kinds import ModelError
from avs_planner.pddl.lite.nodes import FNode, free_variables
from avs_planner.pddl.lite.shared_environment import ENVIRONMENT


class Axiom:
    """One rule: `head(parameters)` holds where `body` does."""

    __slots__ = ("head", "_parameters", "body")

    def __init__(self, head: Fluent, _parameters: OrderedDict[str, Type] | None = None,
                 _env: object = None):
        parameters = OrderedDict((n, Parameter(n, t)) for n, t in (_parameters or {}).items())
        if head.type is not BOOL:
            raise ModelError(f"derived predicate {head.name} is not Boolean")
        if len(parameters) != len(head.signature):
            raise ModelError(f"derived predicate {head.name} takes {len(head.signature)} "
                             f"arguments, the rule's head has {len(parameters)}")
        for parameter, declared in zip(parameters.values(), head.signature, strict=True):
            if not declared.type.is_compatible(parameter.type):
                raise ModelError(f"parameter {parameter.name} of a rule for {head.name} is "
                                 f"not of type {declared.type}")
        self.head = head
        self._parameters = parameters
        self.body: FNode = ENVIRONMENT.expression_manager.TRUE()

    @property
    def name(self) -> str:
        return self.head.name

    @property
    def parameters(self) -> list[Parameter]:
        return list(self._parameters.values())

    def parameter(self, name: str) -> Parameter:
        return self._parameters[name]

    def set_body(self, body: Any) -> None:
        (node,) = ENVIRONMENT.expression_manager.auto_promote(body)
        if node.type is not BOOL:
            raise ModelError(f"the body of a rule for {self.name} is not Boolean")
        if free_variables(node):
            raise ModelError(f"the body of a rule for {self.name} has unbound variables")
        self.body = node

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Axiom) and other.head == self.head
                and other._parameters == self._parameters and other.body is self.body)

    def __hash__(self) -> int:
        return hash(self.head) + sum(map(hash, self._parameters.items())) + hash(self.body)

    def __repr__(self) -> str:
        params = ", ".join(map(str, self.parameters))
        return f"derived {self.name}({params}) := {self.body}"
