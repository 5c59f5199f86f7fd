"""The continual-planning loop's planner side: plan, monitor, replan, give up.

The switching loop owns execution. After each action or observation it hands over the new
belief state (`WorldState`, and a new `ProbabilisticProblem` only when objects changed) and
calls `update`; the planner keeps the rest of the current plan when it is still valid, renames
virtual objects that a detection matched, and otherwise replans. Grounding structure is cached
across these calls, so a replan in an unchanged domain only re-evaluates the state.

Grounding takes the whole initial state (true atoms and numeric values) from the `WorldState`,
never from the problem's :init, so a problem holding only the domain, the objects and the goal
is enough when every call passes a state (the switching loop builds one such problem per
object set and reuses it, which keeps the grounding cache warm). Assumptive steps that came
true (see `matching.confirmed_assumptions`) leave the plan in `update`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from enum import Enum

from avs_planner.cp.grounding import GroundingCache, ground, world_state
from avs_planner.cp.matching import (
    confirmed_assumptions,
    match_virtual_objects,
    rename_plan,
)
from avs_planner.cp.monitor import DEFAULT_PROBABILITY_THRESHOLD, MonitorReport, monitor
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanResult, PlanStatus, PlanStep, SearchOptions
from avs_planner.cp.task import Atom, WorldState
from avs_planner.pddl.model import ProbabilisticProblem


class Decision(Enum):
    CONTINUE = "continue"
    REPLANNED = "replanned"
    GIVE_UP = "give_up"


@dataclass(frozen=True)
class Update:
    """What `ContinualPlanner.update` decided, why, and the plan to follow now."""

    decision: Decision
    report: MonitorReport | None
    plan: tuple[PlanStep, ...]
    result: PlanResult | None = None
    matched: Mapping[str, str] | None = None
    confirmed: tuple[str, ...] = ()  # assumptive steps that came true and were dropped


class ContinualPlanner:
    """Holds the current problem and plan; replans when the monitor says the plan broke."""

    def __init__(
        self,
        pproblem: ProbabilisticProblem,
        options: SearchOptions | None = None,
        min_success: float = 0.0,
        probability_threshold: float = DEFAULT_PROBABILITY_THRESHOLD,
        cache: GroundingCache | None = None,
    ):
        self.pproblem = pproblem
        self.options = (options or SearchOptions()).check()
        self.min_success = min_success
        self.threshold = probability_threshold
        self.cache = cache or GroundingCache()
        self.state = world_state(pproblem.model)
        self.plan: tuple[PlanStep, ...] = ()
        self.results: list[PlanResult] = []

    def replan(self, state: WorldState | None = None) -> PlanResult:
        """Plan from `state` (default: the last state given); the plan becomes current."""
        if state is not None:
            self.state = state
        result = plan(self.pproblem, self.options, self.state, self.cache)
        if result.solved and result.probability < self.min_success:
            result = PlanResult(
                PlanStatus.NO_PLAN_ABOVE_THRESHOLD, planning_time_s=result.planning_time_s,
                expanded=result.expanded, generated=result.generated, reward=result.reward,
                heuristic=result.heuristic, weight=result.weight,
                extra={**result.extra, "best_probability": result.probability},
            )
        self.results.append(result)
        self.plan = result.plan
        return result

    def advance(self, steps: int = 1) -> None:
        """The executor finished (or skipped, for assumptions) the next `steps` steps."""
        self.plan = self.plan[steps:]

    def check(self, state: WorldState | None = None) -> MonitorReport:
        """Monitor the rest of the current plan in `state` without changing anything."""
        task = ground(self.pproblem, state or self.state, self.cache)
        return monitor(self.plan, task, threshold=self.threshold)

    def update(
        self,
        state: WorldState,
        pproblem: ProbabilisticProblem | None = None,
        observed: Mapping[str, Iterable[Atom]] | None = None,
    ) -> Update:
        """New beliefs arrived: keep the plan if still valid (after matching), else replan."""
        before = (self.pproblem, self.state)
        if pproblem is not None:
            self.pproblem = pproblem
        self.state = state
        task = ground(self.pproblem, state, self.cache)
        tasks = [task]
        if any(s.assumptive and task.action(s.name, s.args) is None for s in self.plan):
            tasks.append(ground(*before, self.cache))  # where the plan was made or last held
        matched: dict[str, str] = {}
        if observed:
            matched = match_virtual_objects(self.plan, tasks, observed)
        drop = set(confirmed_assumptions(self.plan, tasks, state.true_atoms, matched))
        confirmed = tuple(s.label for i, s in enumerate(self.plan) if i in drop)
        if drop:
            self.plan = tuple(s for i, s in enumerate(self.plan) if i not in drop)
        if matched:
            self.plan = tuple(rename_plan(self.plan, matched))
        report = monitor(self.plan, task, threshold=self.threshold)
        if report.valid and (report.probability >= self.min_success):
            return Update(Decision.CONTINUE, report, self.plan, matched=matched,
                          confirmed=confirmed)
        result = self.replan()
        decision = Decision.REPLANNED if result.solved else Decision.GIVE_UP
        return Update(decision, report, self.plan, result, matched, confirmed)
