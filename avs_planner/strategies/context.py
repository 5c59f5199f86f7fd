"""What a strategy searches with: the robot adapter, the mind and its helpers, budgets."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from avs_planner.body import RobotBody
from avs_planner.episode.executor import Executor
from avs_planner.episode.mind import Mind
from avs_planner.episode.outcome import Outcome, SearchResult
from avs_planner.episode.robot_api import Robot
from avs_planner.episode.state_builder import StateBuilder
from avs_planner.episode.trace import Trace


@dataclass
class SearchContext:
    """One episode's shared parts. `robot` is the robot through its fence (pose, moves,
    sensing, clock: `episode/robot_api.py`), never the simulator; `options` are the
    strategy's checked options."""

    robot: Robot
    body: RobotBody
    mind: Mind
    builder: StateBuilder
    executor: Executor
    trace: Trace
    target: str
    category: str | None = None
    time_budget_s: float = 1200.0
    wall_budget_s: float = 600.0
    options: Mapping[str, Any] = field(default_factory=dict)
    should_stop: Callable[[], bool] = lambda: False
    dump_dir: str | None = None
    start_clock: float = 0.0
    qsr: Any = None  # QsrKnowledge with the task's own QSR descriptions, or None (defaults)
    # a task counting every instance (`harness/tasks.py`) stops when P(another one in space
    # not yet searched) falls below this level, the task's own; a strategy with a give-up rule
    # of its own (weighing the reward against costs) leaves the stop to that level
    stop_below: float | None = None
    # the episode's use of an experience store (`conceptual_map.knowledge.experience.
    # ExperienceSession`): learned QSR counts are read from it and added to it; None: none
    experience: Any = None

    def budget_spent(self) -> str | None:
        """Why the search must stop now (a request, the simulated or wall budget), or None."""
        if self.should_stop():
            return "stopped on request"
        if self.robot.clock - self.start_clock > self.time_budget_s:
            return f"simulated time budget {self.time_budget_s:g} s spent"
        if self.trace.wall > self.wall_budget_s:
            return f"wall time budget {self.wall_budget_s:g} s spent"
        return None

    def end(self, result: SearchResult, outcome: Outcome, reason: str) -> SearchResult:
        """Record how the search ended (a `done` event) and return `result`."""
        result.outcome, result.reason = outcome, reason
        self.trace.emit("done", outcome=outcome.value, reason=reason)
        return result
