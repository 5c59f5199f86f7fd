"""Weighted A* on g = c + R(1 - p) over a `GroundTask` (the "Switching Planner" of the active
visual search paper by Göbelbecker et al.).

A node carries its cost c and success probability p. Two paths to the same state are only
merged when one dominates the other in both c and p, because the better g now need not be
the better g later (the rest of the plan scales R(1 - p)). With an admissible heuristic and
weight 1 the first goal popped is optimal for the objective.

`SearchOptions.engine` picks where it runs: the Python engine (`python_search.py`) or its C
port `avs_planner/cp/_native.c` (native, packed by `avs_planner.cp.native`), which returns the
same plan and the same expanded/generated counts; "auto" takes the C port when it was built.

This module is the entry point, `search`, and the path callers import the search's names
from; each concept lives in its own module and is re-exported here:
`search_options.py` (what a call is asked for), `plan_result.py` (what it returns and the
objective), `search_modes.py` (when successors are evaluated, which open lists exist),
`pareto.py` (the per-state Pareto labels) and `python_search.py` (the Python engine).
"""

from __future__ import annotations

import time

from avs_planner.cp import native
from avs_planner.cp.plan_result import (
    PlanResult,
    PlanStatus,
    PlanStep,
    _finish,
    objective,
)
from avs_planner.cp.python_search import POP_ORDER, STALL, _Search
from avs_planner.cp.search_modes import (
    DEFERRED,
    DEFERRED_UNHELPFUL,
    EAGER,
    _goal_count,
    _lazy,
    _preferred,
)
from avs_planner.cp.search_options import (
    DEFAULT_PATIENCE,
    DEFAULT_REWARD,
    ENGINES,
    SearchOptions,
)
from avs_planner.cp.symmetry import NO_SYMMETRIES, Symmetries
from avs_planner.cp.task import GroundTask

__all__ = [
    "DEFAULT_PATIENCE",
    "DEFAULT_REWARD",
    "DEFERRED",
    "DEFERRED_UNHELPFUL",
    "EAGER",
    "ENGINES",
    "POP_ORDER",
    "STALL",
    "PlanResult",
    "PlanStatus",
    "PlanStep",
    "SearchOptions",
    "objective",
    "search",
]


def search(
    task: GroundTask,
    options: SearchOptions | None = None,
    symmetries: Symmetries = NO_SYMMETRIES,
) -> PlanResult:
    """Weighted A* from `task.init`; times itself (search only, not grounding)."""
    options = (options or SearchOptions()).check()
    start = time.perf_counter()
    if task.goal_impossible:
        return _finish(task, options, PlanStatus.UNSOLVABLE, None, start, 0, 0)
    if options.engine_used == "native":
        return _native_search(task, options, start, symmetries)
    return _Search(task, options, start, symmetries).run()


def _native_search(
    task: GroundTask, options: SearchOptions, start: float, symmetries: Symmetries
) -> PlanResult:
    status, path, expanded, generated, stopped = native.run(
        task, options.heuristic, options.reward, options.weight, options.min_success,
        options.timeout_s, options.node_limit, options.patience_used, _lazy(task, options),
        _preferred(options), symmetries, start, options.threads, _goal_count(options),
        options.commute,
    )
    steps = task.steps(path)
    return _finish(task, options, PlanStatus(status), steps, start, expanded, generated,
                   engine="native", stopped_by=stopped)
