"""Decision makers for a multi-label session, chosen by name from a registry.

A policy sees the exact factored belief and the remaining step budget, proposes an action,
and is told what happened: "lookahead" is the fast policy (`avs_planner.dt.multi.lookahead`),
"exact" the optimal solver for small instances (`avs_planner.dt.multi.exact`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from avs_planner.dt.errors import DtInputError
from avs_planner.dt.multi.belief import MultiLabelBelief
from avs_planner.dt.multi.domain import MultiAction, MultiObservation
from avs_planner.dt.multi.exact import MultiExactPolicy
from avs_planner.dt.multi.lookahead import MultiLookaheadPolicy
from avs_planner.dt.multi.problem import MultiLabelProblem


class MultiPolicy(Protocol):
    name: str

    def decide(self, belief: MultiLabelBelief, steps_left: int) -> MultiAction: ...

    def observe(self, action: MultiAction, observation: MultiObservation) -> None: ...


MultiPolicyFactory = Callable[[MultiLabelProblem], MultiPolicy]

MULTI_POLICIES: dict[str, MultiPolicyFactory] = {
    "lookahead": MultiLookaheadPolicy,
    "exact": MultiExactPolicy,
}


def make_multi_policy(name: str, problem: MultiLabelProblem) -> MultiPolicy:
    """The policy registered under `name`; DtInputError listing the names otherwise."""
    factory = MULTI_POLICIES.get(name)
    if factory is None:
        raise DtInputError(f"unknown multi-label DT policy {name!r}; choose one of "
                           f"{sorted(MULTI_POLICIES)}")
    return factory(problem)
