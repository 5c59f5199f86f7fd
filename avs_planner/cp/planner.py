"""The thin entry point: ground (cached) then search; times both together."""

from __future__ import annotations

import time
from dataclasses import replace

from avs_planner.cp.anytime import anytime_search
from avs_planner.cp.grounding import DEFAULT_CACHE, GroundingCache, gc_paused, ground
from avs_planner.cp.search import PlanResult, SearchOptions, search
from avs_planner.cp.symmetry import NO_SYMMETRIES, Symmetries, find_symmetries
from avs_planner.cp.task import GroundTask, WorldState
from avs_planner.pddl.model import ProbabilisticProblem


def plan(
    pproblem: ProbabilisticProblem,
    options: SearchOptions | None = None,
    state: WorldState | None = None,
    cache: GroundingCache | None = None,
) -> PlanResult:
    """Plan from `state` (default: the problem's :init); planning_time_s includes grounding."""
    options = (options or SearchOptions()).check()
    with gc_paused():
        start = time.perf_counter()
        if state is None:
            state = (DEFAULT_CACHE if cache is None else cache).initial_state(pproblem)
        task = ground(pproblem, state, cache)
        symmetries = (
            find_symmetries(pproblem, state, task) if options.symmetry else NO_SYMMETRIES
        )
        grounded = time.perf_counter()
        result = _search(task, options, symmetries)
        return replace(
            result,
            planning_time_s=time.perf_counter() - start,
            grounding_time_s=grounded - start,
        )


def plan_task(task: GroundTask, options: SearchOptions | None = None) -> PlanResult:
    """Search an already grounded task (e.g. a replan from a new initial bitset)."""
    return _search(task, (options or SearchOptions()).check())


def _search(task: GroundTask, options: SearchOptions, symmetries: Symmetries = NO_SYMMETRIES
            ) -> PlanResult:
    """The anytime schedule when asked for, else one (weighted A*) search."""
    if options.anytime:
        return anytime_search(task, options, symmetries)
    return search(task, options, symmetries)
