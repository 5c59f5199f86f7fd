"""Weighted A* on g = c + R(1 - p) over a `GroundTask` (seed 003, "Switching Planner").

A node carries its cost c and success probability p. Two paths to the same state are only
merged when one dominates the other in both c and p, because the better g now need not be
the better g later (the rest of the plan scales R(1 - p)). With an admissible heuristic and
weight 1 the first goal popped is optimal for the objective.

`SearchOptions.engine` picks where it runs: this module (python) or its C port
`avs_planner/cp/_native.c` (native, packed by `avs_planner.cp.native`), which returns the same
plan and the same expanded/generated counts; "auto" takes the C port when it was built.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field
from enum import Enum

from avs_planner.cp import native
from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.symmetry import NO_SYMMETRIES, Symmetries
from avs_planner.cp.task import GroundAction, GroundTask, atom_str
from avs_planner.errors import PlanningError

DEFAULT_REWARD = 500.0  # as domains/README.md assumes for the AVS domain
DEFAULT_PATIENCE = 2500  # expansions without a better plan (inadmissible heuristics only)
ENGINES = ("auto", "native", "python")  # auto: the compiled core when it was built


class PlanStatus(Enum):
    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"
    NO_PLAN_ABOVE_THRESHOLD = "no_plan_above_threshold"
    TIMEOUT = "timeout"
    NODE_LIMIT = "node_limit"


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
    """The seed's c(pi) + R(1 - p(pi))."""
    return cost + reward * (1.0 - probability)


class _Labels:
    """Per-state Pareto set of (cost, probability, node) labels."""

    def __init__(self) -> None:
        self.by_state: dict[int, list[tuple[float, float, int]]] = {}

    def add(self, state: int, c: float, p: float, node: int, alive: list[bool]) -> bool:
        labels = self.by_state.get(state)
        if labels is None:
            self.by_state[state] = [(c, p, node)]
            return True
        for c0, p0, _ in labels:
            if c0 <= c and p0 >= p:
                return False
        kept = []
        for label in labels:
            if c <= label[0] and p >= label[1]:
                alive[label[2]] = False
            else:
                kept.append(label)
        kept.append((c, p, node))
        self.by_state[state] = kept
        return True


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


EAGER, DEFERRED, DEFERRED_UNHELPFUL = 0, 1, 2  # _lazy's modes (the C core's LAZY_*)
STALL = 64  # DEFERRED_UNHELPFUL: expansions without a lower h after which all are evaluated


def _lazy(task: GroundTask, options: SearchOptions) -> int:
    """When successors are evaluated: as asked, or by default deferred on deterministic tasks
    and, on probabilistic ones, deferred unless reached by a helpful action; never deferred
    with admissible h.

    Deferring all of them on probabilistic tasks hurts: a successor inherits its parent's
    estimate, so a move that brings the goal closer looks no better than a cheaper useless
    step (a view cone for a label nobody looks for), and the search exhausts the plateau of
    such steps first (a 20-place AVS problem: 200,000 expansions without a plan, 14 eager).
    Helpful actions are the relaxed plan's first steps: evaluating their successors at once
    puts the moves the estimate wants first in the queue with their own estimate, and the
    rest (most of a large task's successors: 341 of 346 at the start of a 160-place
    problem) wait to be popped. When h stalls, see STALL and `_Search.flush`."""
    if get_heuristic(options.heuristic).admissible:
        return EAGER
    if options.lazy is not None:
        return DEFERRED if options.lazy else EAGER
    if task.arrays is not None:
        deterministic = bool((task.arrays.probability == 1.0).all())
    else:
        deterministic = all(a.probability == 1.0 for a in task.actions)
    if deterministic:
        return DEFERRED
    return DEFERRED_UNHELPFUL if _preferred(options) and options.heuristic == "ff" else EAGER


POP_ORDER = (1, 0, 3, 2)  # _Search.queues in the order ties are broken


def _goal_count(options: SearchOptions) -> bool:
    """The goal-count lists: asked for, and optimality does not count."""
    return options.goal_count and not get_heuristic(options.heuristic).admissible


def _preferred(options: SearchOptions) -> bool:
    """LAMA's dual queue: only where optimality does not count (and h records helpful
    actions: FF; the native core checks that itself)."""
    return options.preferred and not get_heuristic(options.heuristic).admissible


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


class _Search:
    def __init__(
        self, task: GroundTask, options: SearchOptions, start: float, symmetries: Symmetries
    ):
        self.task, self.options, self.start = task, options, start
        self.symmetries = symmetries
        self.reward, self.weight = options.reward, options.weight
        self.estimator = get_heuristic(options.heuristic).factory(task, options.reward)
        self.h_cache: dict[int, tuple[float, float]] = {}
        self.states: list[int] = []
        self.costs: list[float] = []
        self.probs: list[float] = []
        self.parents: list[int] = []
        self.via: list[int] = []
        self.alive: list[bool] = []
        self.labels = _Labels()
        self.heap: list[tuple[float, float, int]] = []
        # LAMA's dual queue: successors by helpful actions also go to a preferred queue,
        # which is popped more often (boosted whenever h improves); off when optimality counts
        self.helpful: dict[int, frozenset[int]] | None = getattr(self.estimator, "helpful", None)
        if not _preferred(options):
            self.helpful = None
        self.pref_heap: list[tuple[float, float, int]] = []
        # _goal_count: a goal-count list and its helpful-actions list beside them (LAMA)
        self.count_goals = _goal_count(options)
        self.gc_heap: list[tuple[float, float, int]] = []
        self.gc_pref: list[tuple[float, float, int]] = []
        self.queues = (self.heap, self.pref_heap, self.gc_heap, self.gc_pref)
        self.priority = [0, 0, 0, 0]
        self.best_h = self.best_gc = math.inf
        self.from_queue = 0  # which of self.queues pop() took the node from
        self.popped_h = 0.0  # h of the queue entry pop() took
        self.pruned_threshold = False
        self.lazy = _lazy(task, options)
        self.h_of_node: list[float] = []
        self.evaluated: list[bool] = []
        self.commutes: dict[tuple[int, int], bool] = {}
        self.commute_pruning = options.commute
        self.patience = options.patience_used
        self.best: tuple[float, int, int] | None = None  # incumbent: (objective, node, expanded)
        self.expanded = self.progress_at = 0  # expansions; when best_h last dropped
        self.defer_now = False  # DEFERRED_UNHELPFUL and h dropped in the last STALL expansions
        self.waiting: list[int] = []  # nodes deferred since the last flush
        self.flushed: set[int] = set()  # evaluated by a flush: their first queue entry is stale

    def f(self, state: int, c: float, p: float) -> float:
        """c + w*hc + R(1 - p exp(-hl)): the weight inflates the remaining cost only; weighting
        the failure risk too would make a lower p look better (f = g + h at w = 1)."""
        est = self.h_cache.get(state)
        if est is None:
            est = self.h_cache[state] = self.estimator(state)
        hc, hl = est
        if hc == math.inf:
            return math.inf
        w = self.weight
        return c + w * hc + self.reward * (1.0 - p * math.exp(-hl))

    def push(
        self, state: int, c: float, p: float, parent: int, action: int, preferred: bool = False
    ) -> None:
        if p <= 0.0 or p < self.options.min_success:
            self.pruned_threshold |= p > 0.0
            return
        node = len(self.states)
        if not self.labels.add(state, c, p, node, self.alive):
            return
        g = objective(c, p, self.reward)
        deferred = self.deferred(parent, preferred)
        if deferred:
            h = self.h_of_node[parent]  # evaluated when popped
        else:
            h = self.f(state, c, p) - g
        self.states.append(state)
        self.costs.append(c)
        self.probs.append(p)
        self.parents.append(parent)
        self.via.append(action)
        self.alive.append(h != math.inf)
        self.h_of_node.append(h)
        self.evaluated.append(not deferred)
        if deferred and self.lazy == DEFERRED_UNHELPFUL:
            self.waiting.append(node)
        if h != math.inf:
            self.queue(g + h, h, node, preferred)
            if self.count_goals:
                self.queue_goal_count(state, h, node, preferred)

    def queue_goal_count(self, state: int, h: float, node: int, preferred: bool) -> None:
        """The goal-count lists: by goal facts left (ties: the node's h, then age)."""
        task = self.task
        count = float((task.goal & ~state).bit_count() + (state & task.goal_neg).bit_count())
        heapq.heappush(self.gc_heap, (count, h, node))
        if preferred:
            heapq.heappush(self.gc_pref, (count, h, node))
        if count < self.best_gc:
            self.best_gc = count
            self.boost()

    def boost(self) -> None:
        """Progress: trust the helpful actions for a while (LAMA's boost of 1000)."""
        self.priority[1] -= 1000
        if self.count_goals:
            self.priority[3] -= 1000

    def deferred(self, parent: int, preferred: bool) -> bool:
        """Whether a successor of `parent` is evaluated only when popped (see _lazy)."""
        if parent < 0:
            return False
        return self.lazy == DEFERRED or (self.defer_now and not preferred)

    def queue(self, f: float, h: float, node: int, preferred: bool) -> None:
        heapq.heappush(self.heap, (f, h, node))
        if preferred:
            heapq.heappush(self.pref_heap, (f, h, node))
        if h < self.best_h and self.evaluated[node]:
            self.best_h = h
            self.progress_at = self.expanded
            self.boost()

    def pop(self) -> int:
        """Next node: from the non-empty queue that has had the fewest turns (ties: the
        preferred one, then the main one, then the goal-count ones)."""
        pick = -1
        for i in POP_ORDER:
            if self.queues[i] and (pick < 0 or self.priority[i] < self.priority[pick]):
                pick = i
        self.from_queue = pick
        self.priority[pick] += 1
        _, self.popped_h, node = heapq.heappop(self.queues[pick])
        return node

    def flush(self) -> None:
        """DEFERRED_UNHELPFUL after STALL expansions without a lower h: every node still
        waiting for its estimate gets it now and is queued again by it, as if it had been
        evaluated when generated (the entry it was queued with, its parent's h, is stale)."""
        for node in self.waiting:
            if not self.alive[node] or self.evaluated[node]:
                continue
            self.evaluated[node] = True
            self.flushed.add(node)
            c, p = self.costs[node], self.probs[node]
            f = self.f(self.states[node], c, p)
            if f == math.inf:
                self.alive[node] = False
                continue
            h = f - objective(c, p, self.reward)
            self.h_of_node[node] = h
            self.queue(f, h, node, False)
        self.waiting = []

    def commute(self, i: int, j: int) -> bool:
        key = (i, j)
        value = self.commutes.get(key)
        if value is None:
            value = self.commutes[key] = self.task.actions[i].commutes_with(self.task.actions[j])
        return value

    def evaluate(self, node: int) -> bool:
        """Deferred evaluation: True if the node may be expanded now, else it was re-queued."""
        if self.evaluated[node]:
            return True
        self.evaluated[node] = True
        c, p = self.costs[node], self.probs[node]
        f = self.f(self.states[node], c, p)
        if f == math.inf:
            self.alive[node] = False
            return False
        h = f - objective(c, p, self.reward)
        self.h_of_node[node] = h
        if self.from_queue < 2:  # goal-count keys do not change with h: expanded now
            heap = self.queues[self.from_queue]
            if heap and f > heap[0][0]:
                self.queue(f, h, node, self.from_queue == 1)
                return False
        if h < self.best_h:
            self.best_h = h
            self.progress_at = self.expanded
            self.boost()
        return True

    def run(self) -> PlanResult:
        task, options = self.task, self.options
        self.push(task.init, 0.0, 1.0, -1, -1)
        expanded = 0
        actions = task.actions
        symmetries = self.symmetries
        while any(self.queues):
            node = self.pop()
            if not self.alive[node]:
                continue
            if node in self.flushed and self.popped_h != self.h_of_node[node]:
                continue  # queued by its parent's h before the flush queued it by its own
            if not self.evaluate(node):
                continue
            self.alive[node] = False
            state, c, p = self.states[node], self.costs[node], self.probs[node]
            if task.is_goal(state):
                obj = objective(c, p, self.reward)
                if self.best is None or obj < self.best[0]:
                    self.best = (obj, node, expanded)
                if self.from_queue and self.heap and self.heap[0][0] < obj:
                    # a goal from another list is only taken if no open node promises better
                    self.alive[node] = True
                    heapq.heappush(self.heap, (obj, 0.0, node))
                    continue
                return self.finish(PlanStatus.SOLVED, node, expanded)
            expanded += 1
            self.expanded = expanded
            self.defer_now = (self.lazy == DEFERRED_UNHELPFUL
                              and expanded - self.progress_at <= STALL)
            if self.lazy == DEFERRED_UNHELPFUL and not self.defer_now and self.waiting:
                self.flush()
            if self.best is not None and expanded - self.best[2] > self.patience:
                return self.stop("patience", PlanStatus.SOLVED, expanded)
            if options.node_limit is not None and expanded > options.node_limit:
                return self.stop("node_limit", PlanStatus.NODE_LIMIT, expanded)
            if options.timeout_s is not None:
                if time.perf_counter() - self.start > options.timeout_s:
                    return self.stop("timeout", PlanStatus.TIMEOUT, expanded)
            last = self.via[node]
            helpful = self.helpful.get(state, frozenset()) if self.helpful is not None else ()
            for a in actions:
                if (state & a.pre) == a.pre and not (state & a.pre_neg):
                    if a.clauses and not a.applicable(state):
                        continue
                    if self.commute_pruning and last > a.index and self.commute(a.index, last):
                        continue  # the order (a, last) is explored instead
                    if symmetries.checks and symmetries.prunes(a.index, state):
                        continue  # a mirror image with a lower object is explored
                    succ = (state & ~a.delete) | a.add
                    self.push(
                        succ, c + a.cost, p * a.probability, node, a.index, a.index in helpful
                    )
        status = (
            PlanStatus.NO_PLAN_ABOVE_THRESHOLD if self.pruned_threshold else PlanStatus.UNSOLVABLE
        )
        return self.finish(status, None, expanded)

    def stop(self, why: str, status: PlanStatus, expanded: int) -> PlanResult:
        """A limit was hit: the best plan found so far if there is one, else `status`."""
        if self.best is None:
            return self.finish(status, None, expanded)
        return self.finish(PlanStatus.SOLVED, self.best[1], expanded, stopped_by=why)

    def finish(
        self, status: PlanStatus, node: int | None, expanded: int, stopped_by: str | None = None
    ) -> PlanResult:
        path: list[int] = []
        while node is not None and node >= 0 and self.via[node] >= 0:
            path.append(self.via[node])
            node = self.parents[node]
        path.reverse()
        steps = self.task.steps(path)
        return _finish(
            self.task, self.options, status, steps, self.start, expanded, len(self.states),
            engine="python", stopped_by=stopped_by,
        )


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
