"""Decision makers for a DT session, chosen by name from a registry.

Every policy sees the exact belief and the remaining step budget, proposes an action, and is
told what happened. The POMDP planners ("pouct", "exact") and the baselines ("greedy",
"sweep") share this interface so sessions, simulations and benchmarks can swap them.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from avs_planner.dt.baselines import GreedyPolicy, SweepPolicy
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import DTAction, DTObservation
from avs_planner.dt.errors import DtInputError
from avs_planner.dt.exact import ExactPolicy
from avs_planner.dt.pouct import POUCTPolicy, SearchBudget
from avs_planner.dt.problem import DTProblem


class DTPolicy(Protocol):
    name: str

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction: ...

    def observe(self, action: DTAction, observation: DTObservation) -> None: ...


@dataclass(frozen=True)
class PolicyConfig:
    """Seed and planning budget (used by the planners that search)."""

    seed: int = 0
    budget: SearchBudget = field(default_factory=SearchBudget)


PolicyFactory = Callable[[DTProblem, PolicyConfig], DTPolicy]

POLICIES: dict[str, PolicyFactory] = {
    "pouct": lambda problem, config: POUCTPolicy(problem, config.seed, config.budget),
    "exact": lambda problem, config: ExactPolicy(problem),
    "greedy": lambda problem, config: GreedyPolicy(problem),
    "sweep": lambda problem, config: SweepPolicy(problem),
}


def make_policy(name: str, problem: DTProblem, config: PolicyConfig | None = None) -> DTPolicy:
    """The policy registered under `name`; DtInputError listing the names otherwise."""
    factory = POLICIES.get(name)
    if factory is None:
        raise DtInputError(f"unknown DT policy {name!r}; choose one of {sorted(POLICIES)}")
    return factory(problem, config or PolicyConfig())


def timed_decision(policy: DTPolicy, belief: TargetBelief, steps_left: int):
    """(action, wall seconds) of one decision."""
    start = time.perf_counter()
    action = policy.decide(belief, steps_left)
    return action, time.perf_counter() - start
