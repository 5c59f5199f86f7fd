"""Exact finite-horizon solution of small view-cone searches, and exact policy evaluation.

Value iteration over the reachable belief tree: a belief is fixed by the robot position, the
last detection and the hit/miss counts per cone, so beliefs are memoised by that key and each
is solved once per remaining step budget. Feasible for a handful of cones; used to measure how
close POUCT and greedy get.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    ActionKind,
    DTAction,
    DTObservation,
)
from avs_planner.dt.errors import DtInputError
from avs_planner.dt.models import valid_actions
from avs_planner.dt.problem import DTProblem

BeliefPolicy = Callable[[TargetBelief, int], DTAction]


@dataclass(frozen=True)
class ExactSolution:
    """Optimal expected reward (minus expected cost) and first action for a belief."""

    value: float
    action: DTAction
    beliefs_solved: int


def outcomes(problem: DTProblem, belief: TargetBelief,
             action: DTAction) -> list[tuple[float, TargetBelief]]:
    """(probability, next belief) for each observation `action` can produce."""
    if action.kind is not ActionKind.PROCESS_VIEW_CONE:
        return [(1.0, belief.after(action, NOTHING, problem.detector))]
    p_hit = belief.p_detect(action.cone, problem.detector)
    branches = []
    for p, obs in ((p_hit, DETECTED), (1.0 - p_hit, NOT_DETECTED)):
        if p > 0.0:
            branches.append((p, belief.after(action, obs, problem.detector)))
    return branches


def immediate_reward(problem: DTProblem, belief: TargetBelief, action: DTAction) -> float:
    """Expected reward of `action` under `belief` (costs and terminal penalties)."""
    kind, rewards = action.kind, problem.rewards
    if kind is ActionKind.MOVE:
        return -problem.travel_cost(belief.robot, action.cone)
    if kind is ActionKind.PROCESS_VIEW_CONE:
        return -problem.sensing_cost
    if kind is ActionKind.CONFIRM:
        return -rewards.false_confirm_penalty * (1.0 - belief.probs[action.cone])
    return -rewards.miss_penalty * belief.p_present


class ExactSolver:
    """Optimal values over the belief tree with at most `steps_left` MOVE/PROCESS actions."""

    def __init__(self, problem: DTProblem, max_beliefs: int = 2_000_000):
        self.problem = problem
        self.max_beliefs = max_beliefs
        self._memo: dict[tuple, tuple[float, DTAction]] = {}

    def solve(self, belief: TargetBelief, steps_left: int) -> ExactSolution:
        """Optimal value and action; DtInputError if the tree exceeds `max_beliefs`."""
        value, action = self._value(belief, steps_left)
        return ExactSolution(value, action, len(self._memo))

    def _value(self, belief: TargetBelief, steps_left: int) -> tuple[float, DTAction]:
        key = (belief.key, steps_left)
        cached = self._memo.get(key)
        if cached is not None:
            return cached
        if len(self._memo) >= self.max_beliefs:
            raise DtInputError(f"exact solver: more than {self.max_beliefs} beliefs; "
                               "the instance is too large for exact solution")
        best = max(((self._q(belief, a, steps_left), a) for a in self._actions(belief, steps_left)),
                   key=lambda qa: qa[0])
        self._memo[key] = best
        return best

    def _actions(self, belief: TargetBelief, steps_left: int) -> list[DTAction]:
        actions = valid_actions(self.problem, belief.robot, belief.detected, belief.done,
                                belief.after_move and steps_left > 0)
        if steps_left <= 0:
            return [a for a in actions if a.terminal]
        return actions

    def _q(self, belief: TargetBelief, action: DTAction, steps_left: int) -> float:
        reward = immediate_reward(self.problem, belief, action)
        if action.terminal:
            return reward
        return reward + sum(p * self._value(nxt, steps_left - 1)[0]
                            for p, nxt in outcomes(self.problem, belief, action))


def evaluate_policy(problem: DTProblem, policy: BeliefPolicy, belief: TargetBelief,
                    steps_left: int) -> float:
    """Exact expected reward of a deterministic policy of (belief, steps_left), by enumerating
    observations; the step budget forces CONFIRM/REJECT as in a session."""
    memo: dict[tuple, float] = {}

    def value(b: TargetBelief, k: int) -> float:
        key = (b.key, k)
        if key not in memo:
            action = policy(b, k)
            if k <= 0 and not action.terminal:
                raise DtInputError(f"policy chose {action} with no steps left")
            reward = immediate_reward(problem, b, action)
            if not action.terminal:
                reward += sum(p * value(nxt, k - 1) for p, nxt in outcomes(problem, b, action))
            memo[key] = reward
        return memo[key]

    return value(belief, steps_left)


class ExactPolicy:
    """Optimal finite-horizon decisions (small instances only)."""

    name = "exact"

    def __init__(self, problem: DTProblem, max_beliefs: int = 2_000_000):
        self.solver = ExactSolver(problem, max_beliefs)

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction:
        return self.solver.solve(belief, steps_left).action

    def observe(self, action: DTAction, observation: DTObservation) -> None:
        """Stateless: the memo is keyed by belief."""
