"""What a search call returns: `PlanStatus`, `PlanStep`, `PlanResult` and the objective.

The objective c(pi) + R(1 - p(pi)) of the active visual search paper (Göbelbecker et al.) is
defined here once: the Python engine's g and every result's `objective` use it. `_finish` builds
a `PlanResult` from a plan's ground actions the same way for both engines, so their results
differ only in `extra["engine"]`.
The result types are the planner's public shape (`avs plan --json`, the HTTP service, the
episode loop), kept apart from the search that fills them.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from enum import Enum

from avs_planner.cp.search_options import DEFAULT_REWARD, SearchOptions
from avs_planner.cp.task import GroundAction, GroundTask, atom_str


class PlanStatus(Enum):
    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    NO_PLAN_ABOVE_THRESHOLD = "no_plan_above_threshold"
    TIMEOUT = "timeout"
    NODE_LIMIT = "node_limit"


@dataclass(frozen=True)
class PlanStep:
    """One grounded action of a plan."""

    name: str
    args: tuple[str, ...]
    cost: float
    probability: float
    assumptive: bool = False

    @property
    def label(self) -> str:
        return atom_str((self.name, *self.args))

    @classmethod
    def of(cls, action: GroundAction) -> PlanStep:
        return cls(action.name, action.args, action.cost, action.probability, action.assumptive)


@dataclass(frozen=True)
class PlanResult:
    """Outcome of one planning call; `plan` is empty unless status is SOLVED."""

    status: PlanStatus
    plan: tuple[PlanStep, ...] = ()
    cost: float = 0.0
    probability: float = 0.0
    objective: float = math.inf
    planning_time_s: float = 0.0
    expanded: int = 0
    generated: int = 0
    reward: float = DEFAULT_REWARD
    heuristic: str = ""
    weight: float = 1.0
    grounding_time_s: float = 0.0
    extra: dict = field(default_factory=dict)
    stopped_by: str | None = None
    """Set when a limit ("timeout", "node_limit") or the patience ran out after a plan was
    found: the plan is the best found so far, not one the search showed nothing beats."""

    @property
    def solved(self) -> bool:
        return self.status is PlanStatus.SOLVED

    def as_json(self) -> dict:
        """The JSON shape `avs plan --json` and the HTTP service rely on."""
        return {
            "status": self.status.value,
            "plan": [s.label for s in self.plan],
            "cost": self.cost,
            "probability": self.probability,
            "objective": self.objective if math.isfinite(self.objective) else None,
            "planning_time_s": self.planning_time_s,
            "grounding_time_s": self.grounding_time_s,
            "expanded": self.expanded,
            "generated": self.generated,
            "reward": self.reward,
            "heuristic": self.heuristic,
            "weight": self.weight,
            "stopped_by": self.stopped_by,
        }


def objective(cost: float, probability: float, reward: float) -> float:
    """The objective c(pi) + R(1 - p(pi)) of the active visual search paper."""
    return cost + reward * (1.0 - probability)


def _finish(
    task: GroundTask,
    options: SearchOptions,
    status: PlanStatus,
    steps: list[GroundAction] | None,
    start: float,
    expanded: int,
    generated: int,
    engine: str | None = None,
    stopped_by: str | None = None,
) -> PlanResult:
    elapsed = time.perf_counter() - start
    extra = {"engine": engine or options.engine_used}
    if status is not PlanStatus.SOLVED or steps is None:
        return PlanResult(
            status, planning_time_s=elapsed, expanded=expanded, generated=generated,
            reward=options.reward, heuristic=options.heuristic, weight=options.weight,
            extra=extra,
        )
    plan = tuple(PlanStep.of(a) for a in steps)
    cost = math.fsum(s.cost for s in plan)
    probability = math.prod(s.probability for s in plan)
    return PlanResult(
        status, plan, cost, probability, objective(cost, probability, options.reward),
        planning_time_s=elapsed, expanded=expanded, generated=generated,
        reward=options.reward, heuristic=options.heuristic, weight=options.weight,
        extra=extra, stopped_by=stopped_by,
    )
