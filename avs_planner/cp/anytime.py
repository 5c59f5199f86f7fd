"""Anytime satisficing search (`SearchOptions.anytime`, `avs plan --anytime`).

LAMA's schedule on our objective: first a greedy best-first search with the FF heuristic,
helpful actions first and deferred evaluation, on unit action costs, in rounds of growing
expansion budgets with FF's open lists alternating with goal-count ones, with and without
helpful actions (LAMA's first iteration, with the goal count where LAMA counts landmarks:
plan length guides it, so it finds a plan fast; see `greedy_search`); then weighted A*
restarted with decreasing weights (5, 3, 2, 1) on the real objective c + R(1 - p). Every
plan is judged by that objective and the best so far is kept; at the deadline it is
returned, with `stopped_by = "timeout"` when a later iteration was still running (and with
`"memory"` when a restart ran out of memory: the plan in hand is kept, as at a deadline). The
deadline is the planning call's (`deadline.Deadline`: `timeout_s` from before grounding):
each search gets the time left and none starts once it has passed. No restart proves its
plan optimal (FF is inadmissible and no search prunes by the incumbent's cost), so the
schedule ends before the deadline only when its last restart ends. Probabilistic tasks
keep their objective: the greedy phase keeps the R(1 - p) term in f, and the restarts use
it unchanged. The optimal mode (weight 1 with h^max, no `anytime`) is untouched.
"""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from avs_planner.cp.deadline import Deadline
from avs_planner.cp.search import PlanResult, PlanStatus, SearchOptions, search
from avs_planner.cp.symmetry import NO_SYMMETRIES, Symmetries
from avs_planner.cp.task import GroundTask

GREEDY_WEIGHT = 1e6  # f = c + w h: with h in plan steps, g only breaks ties (greedy)
WEIGHTS = (5.0, 3.0, 2.0, 1.0)  # LAMA's restarts after its greedy iteration
FIRST_BUDGET = 2000  # expansions of the first greedy round
BUDGET_GROWTH = 4


def unit_cost(task: GroundTask) -> GroundTask:
    """The same task with every action costing 1 (its plans' steps keep their real cost)."""
    if task.arrays is None:
        return task  # hand-built tuples of actions: searched as they are
    actions = copy.copy(task.actions)
    if hasattr(actions, "memo"):
        actions.memo = {}  # the packed native task is per cost vector
    arrays = replace(task.arrays, cost=np.ones(len(task.arrays.cost)))
    return replace(task, actions=actions, arrays=arrays)


def anytime_search(
    task: GroundTask, options: SearchOptions, symmetries: Symmetries = NO_SYMMETRIES,
    deadline: Deadline | None = None,
) -> PlanResult:
    """Greedy first, then restarting weighted A*; the best plan by objective at the end.
    `deadline`: the planning call's (default: `options.timeout_s` from now)."""
    run = AnytimeRun(deadline=deadline)
    for _ in anytime_plans(task, options, symmetries, run):
        pass
    return run.result(options)


@dataclass
class AnytimeRun:
    """What an `anytime_plans` run leaves behind: its best result, expansions, the history of
    improvements and why it stopped early (None: it finished its schedule). `deadline`: when
    it must end; None: `options.timeout_s` after `start` (made before grounding when the run
    is made first, as `planner.improving_plans` callers do)."""

    best: PlanResult = field(default_factory=lambda: PlanResult(PlanStatus.TIMEOUT))
    expanded: int = 0
    history: list[dict] = field(default_factory=list)
    stopped: str | None = None
    start: float = field(default_factory=time.perf_counter)
    deadline: Deadline | None = None

    def deadline_for(self, options: SearchOptions) -> Deadline:
        """The run's deadline, else `options.timeout_s` after its start."""
        if self.deadline is not None:
            return self.deadline
        return Deadline(self.start, options.timeout_s)

    def result(self, options: SearchOptions) -> PlanResult:
        """The best plan with the run's totals (`anytime_search`'s answer)."""
        return _done(self.best, options, self.start, self.expanded, self.history,
                     self.stopped if self.best.solved else None)


def anytime_plans(task: GroundTask, options: SearchOptions,
                  symmetries: Symmetries = NO_SYMMETRIES, run: AnytimeRun | None = None
                  ) -> Iterator[PlanResult]:
    """Each plan better by the objective than the ones before, as the schedule finds it:
    the greedy search's, then each restart's that improves on it (what unified-planning's
    `AnytimePlanner` hands on). `run` collects the totals (`AnytimeRun.result`)."""
    run = run if run is not None else AnytimeRun()
    start = run.start
    deadline = run.deadline_for(options)
    best, expanded = greedy_search(task, options, symmetries, deadline)
    run.best, run.expanded = best, expanded
    if best.solved:
        run.history.append(_entry("greedy", best, start))
        yield _improved(best, options, run)
    elif best.status not in (PlanStatus.TIMEOUT, PlanStatus.NODE_LIMIT):
        return
    run.stopped = None if best.solved else "timeout"
    for weight in WEIGHTS:
        left = deadline.left()
        if left is not None and left <= 0:
            run.stopped = "timeout"
            break
        try:
            result = search(task, replace(options, anytime=False, weight=weight,
                                          timeout_s=left), symmetries)
        except MemoryError:
            # a restart's open list outgrew the memory (IPC maintenance 1 without a timeout,
            # at w = 2 or below): the plan in hand is the answer, as at a deadline
            if not run.best.solved:
                raise
            run.stopped = "memory"
            break
        run.expanded += result.expanded
        if result.solved and result.objective < run.best.objective - 1e-9:
            run.best = result
            run.history.append(_entry(weight, result, start))
            yield _improved(result, options, run)
        if result.status is PlanStatus.TIMEOUT or result.stopped_by == "timeout":
            run.stopped = "timeout"
            break


def _improved(result: PlanResult, options: SearchOptions, run: AnytimeRun) -> PlanResult:
    """A plan as it is handed on mid-run: timed from the run's start, not stopped early."""
    return replace(result, planning_time_s=time.perf_counter() - run.start,
                   expanded=run.expanded, weight=options.weight, stopped_by=None)


@dataclass(frozen=True)
class Variant:
    """One greedy search of a round: its open lists and successor pruning (SearchOptions'
    fields of the same names)."""

    preferred: bool = True
    goal_count: bool = True
    commute: bool = False
    share: int = 1  # its expansion budget: share x the round's

    def label(self) -> str:
        return (f"{'helpful' if self.preferred else 'plain'}"
                f"{'+goal-count' if self.goal_count else ''}"
                f"{'' if self.commute else ', all orders'}")


# FF alone with helpful actions and the pruning of commuting orders, on twice the budget (the
# greedy search that solves IPC floortile 3 and 4, at 1.6 and 3.1 million expansions, where
# the goal-count lists lead into dead ends), then the alternating lists without and with
# helpful actions (tetris 2: 19,580 expansions without them; maintenance 2 and 3: 68 and 61
# without, 805 and 58 with, out of 20,000 with FF's lists alone; barman needs them). A round
# costs the variants before the one that succeeds in full, hence the first one's share:
# floortile's expansions cost ~4 us, tetris's ~130 us.
VARIANTS = (Variant(True, goal_count=False, commute=True, share=2), Variant(False),
            Variant(True))


def greedy_search(task: GroundTask, options: SearchOptions, symmetries: Symmetries,
                  deadline: Deadline | None,
                  variants: tuple[Variant, ...] = VARIANTS) -> tuple[PlanResult, int]:
    """Greedy best-first on unit costs, each variant in turn under an expansion budget that
    grows fourfold per round until one finds a plan or proves there is none; the rounds cost
    at most a small factor over the best variant alone.

    By default (VARIANTS): FF with helpful actions as before, then without and with the
    helpful-actions lists (they make barman easy and mislead on tetris) FF's open lists
    alternating with goal-count lists (LAMA alternates with its landmark count), expanding
    every order of commuting actions (SearchOptions.goal_count, .commute).
    `extra["greedy_round"]` says which round and variant found the plan. Each search gets
    the time `deadline` leaves, and none starts once it has passed (None: no deadline)."""
    unit = unit_cost(task)
    greedy = replace(options, anytime=False, weight=GREEDY_WEIGHT, lazy=True, patience=0)
    budget, expanded = FIRST_BUDGET, 0
    result = PlanResult(PlanStatus.TIMEOUT)
    while True:
        for variant in variants:
            left = None if deadline is None else deadline.left()
            if left is not None and left <= 0:
                return result, expanded
            limit = budget * variant.share
            if options.node_limit is not None:
                limit = min(limit, options.node_limit)
            result = search(unit, replace(greedy, preferred=variant.preferred,
                                          goal_count=variant.goal_count,
                                          commute=variant.commute, node_limit=limit,
                                          timeout_s=left), symmetries)
            expanded += result.expanded
            if result.status is not PlanStatus.NODE_LIMIT:
                round_ = {"budget": limit, "variant": variant.label(),
                          "expanded": result.expanded}
                return replace(result, extra={**result.extra, "greedy_round": round_}), expanded
        if options.node_limit is not None and budget * min(
                v.share for v in variants) >= options.node_limit:
            return result, expanded  # every variant had the whole node limit
        budget *= BUDGET_GROWTH


def _entry(weight: float | str, result: PlanResult, start: float) -> dict:
    return {"weight": weight, "objective": result.objective, "cost": result.cost,
            "time_s": time.perf_counter() - start}


def _done(best: PlanResult, options: SearchOptions, start: float, expanded: int,
          history: list[dict], stopped: str | None) -> PlanResult:
    extra = {**best.extra, "anytime": history}
    return replace(best, planning_time_s=time.perf_counter() - start, expanded=expanded,
                   weight=options.weight, extra=extra,
                   stopped_by=stopped if best.solved else None,
                   objective=best.objective if best.solved else math.inf)
