"""Decision makers for a DT session, chosen by name from a registry.

Every policy sees the exact belief and the remaining step budget, proposes an action, and is
told what happened. The POMDP planners ("pouct", "exact") and the baselines ("greedy",
"sweep") share this interface so sessions, simulations and benchmarks can swap them.
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from avs_planner.dt.agent import ViewConeAgent
from avs_planner.dt.baselines import GreedyPolicy, SweepPolicy
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import DTAction, DTObservation
from avs_planner.dt.errors import DtInputError
from avs_planner.dt.exact import ExactSolver
from avs_planner.dt.pouct import SearchBudget, ViewConePOUCT
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


class POUCTPolicy:
    """pomdp-py POUCT over the agent's histogram belief, reusing the search tree."""

    name = "pouct"

    def __init__(self, problem: DTProblem, config: PolicyConfig):
        self.problem = problem
        self._rng = random.Random(config.seed)
        self._budget = config.budget
        self.agent = ViewConeAgent(problem, self._rng)
        self._planner: ViewConePOUCT | None = None
        self.last_num_sims = 0

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction:
        self._planner = ViewConePOUCT(self.problem, self._rng, steps_left, self._budget)
        action = self._planner.plan_from(self.agent, belief)
        self.last_num_sims = self._planner.last_num_sims
        return action

    def observe(self, action: DTAction, observation: DTObservation) -> None:
        self.agent.update(action, observation)
        if self._planner is not None and getattr(self.agent, "tree", None) is not None:
            self._planner.update(self.agent, action, observation)


class ExactPolicy:
    """Optimal finite-horizon decisions (small instances only)."""

    name = "exact"

    def __init__(self, problem: DTProblem, max_beliefs: int = 2_000_000):
        self.solver = ExactSolver(problem, max_beliefs)

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction:
        return self.solver.solve(belief, steps_left).action

    def observe(self, action: DTAction, observation: DTObservation) -> None:
        """Stateless: the memo is keyed by belief."""


PolicyFactory = Callable[[DTProblem, PolicyConfig], DTPolicy]

POLICIES: dict[str, PolicyFactory] = {
    "pouct": POUCTPolicy,
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
