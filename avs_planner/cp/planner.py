"""The thin entry point: ground (cached) then search; times both together, and one deadline
(`SearchOptions.timeout_s`, `deadline.Deadline`) bounds both: no search starts once grounding
has used up the time, and each search gets what is left."""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import replace

from avs_planner.cp.anytime import AnytimeRun, anytime_plans, anytime_search
from avs_planner.cp.deadline import Deadline
from avs_planner.cp.grounding import DEFAULT_CACHE, GroundingCache, gc_paused, ground
from avs_planner.cp.plan_result import _finish
from avs_planner.cp.search import PlanResult, PlanStatus, SearchOptions, search
from avs_planner.cp.symmetry import NO_SYMMETRIES, Symmetries, find_symmetries
from avs_planner.cp.task import GroundTask, WorldState
from avs_planner.pddl.model import ProbabilisticProblem


def plan(
    pproblem: ProbabilisticProblem,
    options: SearchOptions | None = None,
    state: WorldState | None = None,
    cache: GroundingCache | None = None,
    deadline: Deadline | None = None,
) -> PlanResult:
    """Plan from `state` (default: the problem's :init); planning_time_s includes grounding.
    `deadline`: when the call must end (default: `options.timeout_s` from now; a caller that
    read the files first can start it before); it bounds grounding and search together: a
    TIMEOUT result (no search) when grounding used it up."""
    options = (options or SearchOptions()).check()
    with gc_paused():
        start = time.perf_counter()
        deadline = deadline if deadline is not None else Deadline.from_now(options.timeout_s)
        task, symmetries = _ground(pproblem, options, state, cache)
        grounded = time.perf_counter()
        result = _search(task, options, symmetries, deadline)
        return replace(
            result,
            planning_time_s=time.perf_counter() - start,
            grounding_time_s=grounded - start,
        )


def improving_plans(pproblem: ProbabilisticProblem, options: SearchOptions | None = None,
                    run: AnytimeRun | None = None) -> Iterator[PlanResult]:
    """The anytime schedule's plans as it finds them, each better by the objective than the
    last (`anytime.anytime_plans`), from the problem's :init; `run` collects the totals.
    Times and the deadline (`run.deadline_for`) count grounding."""
    options = (options or SearchOptions()).check()
    run = run if run is not None else AnytimeRun()
    with gc_paused():
        task, symmetries = _ground(pproblem, options)
    plans = anytime_plans(task, options, symmetries, run)
    while True:  # the search runs with the collector paused, the caller's turn does not
        with gc_paused():
            result = next(plans, None)
        if result is None:
            return
        yield result


def _ground(pproblem: ProbabilisticProblem, options: SearchOptions,
            state: WorldState | None = None, cache: GroundingCache | None = None
            ) -> tuple[GroundTask, Symmetries]:
    """The task grounded from `state` (default: the problem's :init), and its symmetries
    when the options ask for them."""
    if state is None:
        state = (DEFAULT_CACHE if cache is None else cache).initial_state(pproblem)
    task = ground(pproblem, state, cache)
    symmetries = find_symmetries(pproblem, state, task) if options.symmetry else NO_SYMMETRIES
    return task, symmetries


def _search(task: GroundTask, options: SearchOptions, symmetries: Symmetries,
            deadline: Deadline) -> PlanResult:
    """The anytime schedule when asked for, else one (weighted A*) search with the time
    left; TIMEOUT without a search when none is left."""
    if options.anytime:
        return anytime_search(task, options, symmetries, deadline)
    left = deadline.left()
    if left is not None and left <= 0:
        return _finish(task, options, PlanStatus.TIMEOUT, None, time.perf_counter(), 0, 0)
    return search(task, replace(options, timeout_s=left), symmetries)
