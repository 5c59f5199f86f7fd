"""The engine "python": weighted A* on g = c + R(1 - p) over a `GroundTask`, the objective of
the active visual search paper (Göbelbecker et al.).

`_Search` is one search call: its nodes (kept by `pareto._Labels`), its open lists (the
main list ordered by f, LAMA's helpful-actions list and the goal-count lists, popped in
turns with boosts), deferred evaluation of successors (`search_modes._lazy`, flushed after
STALL expansions without progress), pruning (commuting orders, symmetries, the success
threshold) and its stopping rules (node limit, timeout, patience); a successor of a task
with derived predicates' rules is closed under them (`ground_axioms.py`). These share the
search's state and run in its inner loop, so they stay one class; the C core `_native.c`
ports it field for field (same plan, same expanded/generated counts). Callers go through
`search.search`, which picks the engine.
"""

from __future__ import annotations

import heapq
import math
import time

from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.pareto import _Labels
from avs_planner.cp.plan_result import PlanResult, PlanStatus, _finish, objective
from avs_planner.cp.search_modes import DEFERRED, DEFERRED_UNHELPFUL, _goal_count, _lazy, _preferred
from avs_planner.cp.search_options import SearchOptions
from avs_planner.cp.symmetry import Symmetries
from avs_planner.cp.task import GroundTask

STALL = 64  # DEFERRED_UNHELPFUL: expansions without a lower h after which all are evaluated
POP_ORDER = (1, 0, 3, 2)  # _Search.queues in the order ties are broken


class _Search:
    """One call of the Python engine (see the module docstring)."""

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
            a, b, axioms = self.task.actions[i], self.task.actions[j], self.task.axioms
            value = self.commutes[key] = (a.commutes_with(b) if axioms is None
                                          else axioms.commutes(a, b))
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
        close = None if task.axioms is None else task.axioms.close  # derived facts
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
                    if close is not None:
                        succ = close(succ)
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
