"""What a search call is asked for: `SearchOptions`, its defaults and its validation.

Both engines (`python_search.py` and the C core through `native.py`) read the same options;
`check` rejects a bad one before either starts, and `patience_used` / `engine_used` resolve the
automatic choices once, so the engines and the result agree on what ran.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from avs_planner.cp import native
from avs_planner.cp.heuristics import get_heuristic
from avs_planner.errors import PlanningError

DEFAULT_REWARD = 500.0  # as domains/README.md assumes for the AVS domain
DEFAULT_PATIENCE = 2500  # expansions without a better plan (inadmissible heuristics only)
ENGINES = ("auto", "native", "python")  # auto: the compiled core when it was built


@dataclass(frozen=True)
class SearchOptions:
    """R (goal reward), weight w of f = g + w h, heuristic name, limits, success threshold."""

    reward: float = DEFAULT_REWARD
    weight: float = 2.0
    heuristic: str = "ff"
    timeout_s: float | None = None
    node_limit: int | None = None
    min_success: float = 0.0
    symmetry: bool = True
    lazy: bool | None = None
    """Deferred evaluation: True evaluates every successor when it is popped (it inherits its
    parent's estimate until then), False every one when it is generated. None: deferred on
    deterministic tasks; on probabilistic ones, successors by a helpful action are evaluated
    when generated and the others when popped (FF with helpful actions only; else eager)."""
    preferred: bool = True  # helpful actions first (dual queue) when h is inadmissible and has them
    goal_count: bool = False
    """A second open list ordered by goal count (goal facts not yet true, negative goal facts
    true), alternated with the heuristic's and, with `preferred`, its own helpful-actions
    list: LAMA's multi-queue search with the goal count where LAMA has its landmark count.
    Boosting on progress of either estimate favours the helpful-action lists. Ignored when h
    is admissible (optimality counts). The anytime mode's greedy phase turns it on."""
    engine: str = "auto"  # "native" (C core, same results), "python", or auto: native if built
    threads: int | None = None
    """Threads the native core evaluates states on (1 or 2; same results either way). None:
    two on a machine with two or more CPUs when the task is large enough for it to pay
    (at least 1,000 (class, precondition) entries in the relaxed task, as the 8- to 20-place
    AVS problems); one otherwise. The Python engine always uses one."""
    commute: bool = True
    """Skip the second order of two commuting actions (b after a where a < b is explored,
    a after b is not). Sound for a search that keeps every node, but it makes a node's
    successors depend on how it was reached, which its estimate (of the state) does not
    see: a greedy search that took a high-numbered action first is held to higher-numbered
    ones below it (IPC maintenance: every `workat` commutes with every other, and the
    greedy phase exhausted 20,000 expansions on instance 2 with it, 805 without). The
    anytime mode's greedy phase turns it off."""
    anytime: bool = False
    """LAMA-style anytime satisficing (`anytime.py`): greedy best-first with FF and helpful
    actions on unit costs, then weighted A* restarts (w = 5, 3, 2, 1) on the objective; the
    best plan by objective when `timeout_s` runs out (or when the last restart ends)."""
    patience: float | None = None
    """Once a plan is found, expansions allowed without finding a better one before the best
    is returned. None: DEFAULT_PATIENCE with an inadmissible heuristic, unlimited
    (math.inf) with an admissible one, so w = 1 stays optimal."""

    def check(self) -> SearchOptions:
        if self.reward < 0 or not math.isfinite(self.reward):
            raise PlanningError(f"reward must be a finite number >= 0, got {self.reward}")
        if self.weight < 1 or not math.isfinite(self.weight):
            raise PlanningError(f"weight must be a finite number >= 1, got {self.weight}")
        if self.timeout_s is not None and self.timeout_s <= 0:
            raise PlanningError(f"timeout must be > 0 seconds, got {self.timeout_s}")
        if self.node_limit is not None and self.node_limit <= 0:
            raise PlanningError(f"node limit must be > 0, got {self.node_limit}")
        if not 0.0 <= self.min_success <= 1.0:
            raise PlanningError(f"success threshold must be in [0, 1], got {self.min_success}")
        get_heuristic(self.heuristic)
        if self.patience is not None and not self.patience >= 0:
            raise PlanningError(f"patience must be >= 0 expansions (or inf), got {self.patience}")
        if self.threads is not None and (type(self.threads) is not int
                                         or self.threads not in (1, 2)):
            raise PlanningError(f"threads must be 1 or 2 (or None: automatic), got "
                                f"{self.threads}")
        if self.engine not in ENGINES:
            raise PlanningError(
                f"unknown engine {self.engine!r} (choose one of: {', '.join(ENGINES)})")
        if self.engine == "native" and not native.AVAILABLE:
            raise PlanningError("engine 'native' asked for but the compiled search core is "
                                "not built (reinstall with `pip install -e .` and a C compiler)")
        if self.engine == "native" and self.heuristic not in native.HEURISTIC_CODES:
            raise PlanningError(f"engine 'native' has no heuristic {self.heuristic!r}")
        return self

    @property
    def patience_used(self) -> float:
        """Expansions without improvement after a plan is found (math.inf: no limit)."""
        if self.patience is not None:
            return self.patience
        return math.inf if get_heuristic(self.heuristic).admissible else DEFAULT_PATIENCE

    @property
    def engine_used(self) -> str:
        """The engine that will run: auto resolves to native when the core is built."""
        if self.engine == "auto":
            supported = native.AVAILABLE and self.heuristic in native.HEURISTIC_CODES
            return "native" if supported else "python"
        return self.engine
