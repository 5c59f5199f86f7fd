"""Relaxed-plan heuristics for the objective c + R(1 - p), chosen by name from a registry.

Every estimator maps a state to a pair (cost part, -log probability part) that depends only
on the state; the search turns it into h(s, p) = hc + R * p * (1 - exp(-hl)) for a node that
got to s with probability p. For h^max both parts are h^max values over action costs and over
-log p(a) respectively, which bound any plan's cost and its -log success probability from
below, so the combination is admissible for the objective. h_add and FF are not; they also
read the clauses the grounder made from forall/imply preconditions (see `RelaxedTask.for_state`),
which h^max must ignore to stay admissible. FF records helpful actions for the search.
"""

from __future__ import annotations

import copy
import heapq
import math
from collections.abc import Callable
from dataclasses import dataclass

from avs_planner.cp.relaxed_merge import merge_task
from avs_planner.cp.task import GroundTask
from avs_planner.errors import PlanningError

INF = math.inf
Estimate = tuple[float, float]
Estimator = Callable[[int], Estimate]


class RelaxedTask:
    """Per-task arrays the relaxed heuristics iterate over (negative preconditions dropped):
    the task's actions, with groups that differ in one argument merged (relaxed_merge.py);
    `n_facts` counts the auxiliary facts of the merge too."""

    def __init__(self, task: GroundTask, reward: float, clauses: bool = False):
        merge = self.merge = merge_task(task)
        self.n_facts = merge.n_rfacts
        self.n_task_actions = n = len(task.actions)
        extra_pre, extra_add = merge.extra_lists()
        self.pre = [a.pre_facts for a in task.actions] + extra_pre
        self.add = [a.add_facts for a in task.actions] + extra_add
        base_cost = [a.cost for a in task.actions]
        base_neglog = [-math.log(a.probability) for a in task.actions]
        # +1 per action (as LAMA's plusone costs): zero-cost actions otherwise form plateaus
        base_combined = [1.0 + a.cost + reward * (1.0 - a.probability) for a in task.actions]
        behind = merge.weight_of.tolist()  # extra actions: a member's weights, or 0 (aux)
        self.cost = base_cost + [base_cost[b] if b >= 0 else 0.0 for b in behind]
        self.neglog = base_neglog + [base_neglog[b] if b >= 0 else 0.0 for b in behind]
        self.combined = base_combined + [base_combined[b] if b >= 0 else 0.0 for b in behind]
        self.aux = [False] * (n + merge.n_merged) + [True] * (merge.n_extra - merge.n_merged)
        self.live = [not x for x in merge.away.tolist()] + [True] * merge.n_extra
        self.pre_of: list[list[int]] = [[] for _ in range(self.n_facts)]
        for i, pre in enumerate(self.pre):
            if self.live[i]:
                for f in pre:
                    self.pre_of[f].append(i)
        self.no_pre = [i for i, pre in enumerate(self.pre) if not pre and self.live[i]]
        self.goal = [i for i in range(self.n_facts) if task.goal >> i & 1]
        self.is_goal = [bool(task.goal >> i & 1) for i in range(self.n_facts)]
        self.pre_len = [len(p) for p in self.pre]
        self.clauses = _unit_clauses(task) if clauses else []
        self._variants: dict[tuple[bool, ...], RelaxedTask] = {}

    def for_state(self, state: int) -> RelaxedTask:
        """The task with each clause (pos or not N) whose N all hold in `state` as a plain
        precondition `pos` (the relaxation cannot make N false, so pos is needed; an
        estimate only: a real plan may delete N). Variants are cached by the active set."""
        if not self.clauses:
            return self
        key = tuple(neg & state == neg for _, _, neg in self.clauses)
        variant = self._variants.get(key)
        if variant is None:
            variant = self._variants[key] = self._with_clauses(key)
        return variant

    def _with_clauses(self, key: tuple[bool, ...]) -> RelaxedTask:
        variant = copy.copy(self)
        variant.clauses, variant._variants = [], {}
        pre = [list(p) for p in self.pre]
        for (a, f, _), active in zip(self.clauses, key, strict=True):
            if active and f not in pre[a]:
                pre[a].append(f)
        variant.pre = [tuple(p) for p in pre]
        variant.pre_of = [[] for _ in range(self.n_facts)]
        for i, p in enumerate(variant.pre):
            if self.live[i]:
                for f in p:
                    variant.pre_of[f].append(i)
        variant.no_pre = [i for i, p in enumerate(variant.pre) if not p and self.live[i]]
        variant.pre_len = [len(p) for p in variant.pre]
        return variant


def _unit_clauses(task: GroundTask) -> list[tuple[int, int, int]]:
    """(action, fact, negative mask) of every clause with one positive fact."""
    out = []
    for a in task.actions:
        for pos, neg in a.clauses:
            if pos and pos & (pos - 1) == 0 and neg:
                out.append((a.index, pos.bit_length() - 1, neg))
    return out


def relaxed_costs(
    rt: RelaxedTask, state: int, weights: list[float], use_max: bool
) -> tuple[list[float], list[int]]:
    """Generalised Dijkstra: cost of each fact (h^max or h^add) and its best supporter."""
    dist = [INF] * rt.n_facts
    support = [-1] * rt.n_facts
    heap: list[tuple[float, int]] = []
    bits, f = state, 0
    while bits:
        if bits & 1:
            dist[f] = 0.0
            heap.append((0.0, f))
        bits >>= 1
        f += 1
    remaining = rt.pre_len.copy()
    value = [0.0] * len(remaining)
    add, pre_of, push, pop = rt.add, rt.pre_of, heapq.heappush, heapq.heappop
    for a in rt.no_pre:
        nd = weights[a]
        for g in add[a]:
            if nd < dist[g]:
                dist[g] = nd
                support[g] = a
                push(heap, (nd, g))
    goals_left = len(rt.goal)
    is_goal = rt.is_goal
    while heap and goals_left:
        d, f = pop(heap)
        if d > dist[f]:
            continue
        if is_goal[f]:  # a goal fact's value is final once popped (popped once: d == dist)
            goals_left -= 1
        for a in pre_of[f]:
            value[a] = (value[a] if value[a] > d else d) if use_max else value[a] + d
            remaining[a] -= 1
            if remaining[a] == 0:
                nd = value[a] + weights[a]
                for g in add[a]:
                    if nd < dist[g]:
                        dist[g] = nd
                        support[g] = a
                        push(heap, (nd, g))
    return dist, support


def _goal_value(rt: RelaxedTask, dist: list[float], use_max: bool) -> float:
    values = [dist[g] for g in rt.goal]
    if not values:
        return 0.0
    return max(values) if use_max else sum(values)


def _cost_and_risk(rt: RelaxedTask, state: int, use_max: bool) -> Estimate:
    """Relaxed goal cost and −log-probability estimates (max or additive aggregation)."""
    dist, _ = relaxed_costs(rt, state, rt.cost, use_max)
    hc = _goal_value(rt, dist, use_max)
    if hc == INF:
        return INF, INF
    dist, _ = relaxed_costs(rt, state, rt.neglog, use_max)
    return hc, _goal_value(rt, dist, use_max)


def _hmax(task: GroundTask, reward: float) -> Estimator:
    rt = RelaxedTask(task, reward)
    return lambda state: _cost_and_risk(rt, state, True)


def _hadd(task: GroundTask, reward: float) -> Estimator:
    base = RelaxedTask(task, reward, clauses=True)
    return lambda state: _cost_and_risk(base.for_state(state), state, False)


class _FF:
    """h_add on the combined weight c(a) + R(1 - p(a)), then a relaxed plan's own c and -log p.

    Also remembers, per evaluated state, the relaxed plan's actions applicable there: the
    helpful actions (preferred operators) the search may try first, as LAMA does."""

    def __init__(self, task: GroundTask, reward: float):
        self.base = RelaxedTask(task, reward, clauses=True)
        self.actions = task.actions
        self.helpful: dict[int, frozenset[int]] = {}

    def __call__(self, state: int) -> Estimate:
        rt = self.base.for_state(state)
        dist, support = relaxed_costs(rt, state, rt.combined, False)
        if any(dist[g] == INF for g in rt.goal):
            return INF, INF
        chosen = [a for a in self._relaxed_plan(rt, state, support) if not rt.aux[a]]
        actions, n, merge = self.actions, rt.n_task_actions, rt.merge
        real = (a if a < n else merge.member(a, support) for a in chosen)
        self.helpful[state] = frozenset(a for a in real if actions[a].applicable(state))
        return sum(rt.cost[a] + 1.0 for a in chosen), sum(rt.neglog[a] for a in chosen)

    @staticmethod
    def _relaxed_plan(rt: RelaxedTask, state: int, support: list[int]) -> dict[int, None]:
        """The relaxed plan's actions in the order chosen (a dict, not a set: the sums above
        then run in a defined order, which the compiled core reproduces bit for bit)."""
        chosen: dict[int, None] = {}
        stack = [g for g in rt.goal if not state >> g & 1]
        seen: set[int] = set(stack)
        while stack:
            a = support[stack.pop()]
            if a < 0 or a in chosen:
                continue
            chosen[a] = None
            for f in rt.pre[a]:
                if f not in seen and not state >> f & 1:
                    seen.add(f)
                    stack.append(f)
        return chosen


def _ff(task: GroundTask, reward: float) -> Estimator:
    return _FF(task, reward)


def _blind(task: GroundTask, reward: float) -> Estimator:
    def estimate(state: int) -> Estimate:
        return 0.0, 0.0

    return estimate


@dataclass(frozen=True)
class HeuristicSpec:
    """A heuristic's name travels with its factory and whether it is admissible."""

    name: str
    factory: Callable[[GroundTask, float], Estimator]
    admissible: bool
    description: str


HEURISTICS: dict[str, HeuristicSpec] = {
    spec.name: spec
    for spec in (
        HeuristicSpec("hmax", _hmax, True, "probabilistic h^max (admissible; optimal at w=1)"),
        HeuristicSpec("hadd", _hadd, False, "probabilistic h_add (inadmissible)"),
        HeuristicSpec("ff", _ff, False, "FF relaxed plan on c + R(1-p) (inadmissible, default)"),
        HeuristicSpec("blind", _blind, True, "zero (uniform-cost search on the objective)"),
    )
}


def get_heuristic(name: str) -> HeuristicSpec:
    """The registered heuristic called `name`; PlanningError listing the choices otherwise."""
    try:
        return HEURISTICS[name]
    except KeyError:
        known = ", ".join(sorted(HEURISTICS))
        raise PlanningError(f"unknown heuristic {name!r} (choose one of: {known})") from None
