"""Quality metrics: action costs, makespan, an expression on the final state."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from avs_planner.pddl.lite.declarations import _numeric
from avs_planner.pddl.lite.kinds import ModelError
from avs_planner.pddl.lite.nodes import FNode
from avs_planner.pddl.lite.shared_environment import ENVIRONMENT

if TYPE_CHECKING:
    from avs_planner.pddl.lite.actions import InstantaneousAction
    from avs_planner.pddl.lite.shared_environment import Environment


class _Metric:
    @staticmethod
    def is_minimize_action_costs() -> bool:
        return False

    @property
    def environment(self) -> Environment:
        return ENVIRONMENT


class MinimizeActionCosts(_Metric):
    def __init__(self, costs: Mapping[InstantaneousAction, Any], default: Any = None,
                 environment: object = None):
        em = ENVIRONMENT.expression_manager
        self.costs: dict[InstantaneousAction, FNode] = {}
        for action, cost in costs.items():
            (node,) = em.auto_promote(cost)
            if not _numeric(node.type):
                raise ModelError("action costs must be numeric")
            self.costs[action] = node
        self.default: FNode | None = None
        if default is not None:
            (self.default,) = em.auto_promote(default)
            if not _numeric(self.default.type):
                raise ModelError("the default action cost must be numeric")

    @staticmethod
    def is_minimize_action_costs() -> bool:
        return True

    def get_action_cost(self, action: InstantaneousAction) -> FNode | None:
        return self.costs.get(action, self.default)

    def __repr__(self) -> str:
        costs: dict[str, FNode | None] = {a.name: c for a, c in self.costs.items()}
        costs["default"] = self.default
        return f"minimize actions-cost: {costs}"


class MinimizeMakespan(_Metric):
    def __repr__(self) -> str:
        return "minimize makespan"


class _ExpressionMetric(_Metric):
    _word = ""

    def __init__(self, expression: Any, environment: object = None):
        (self.expression,) = ENVIRONMENT.expression_manager.auto_promote(expression)
        if not _numeric(self.expression.type):
            raise ModelError("a metric expression must be numeric")

    def __repr__(self) -> str:
        return f"{self._word} {self.expression}"


class MinimizeExpressionOnFinalState(_ExpressionMetric):
    _word = "minimize"


class MaximizeExpressionOnFinalState(_ExpressionMetric):
    _word = "maximize"
