"""Exact finite-horizon solution of small multi-label searches, and exact policy evaluation:
the test oracle of the online policy.

As in the single-label solver, a belief is fixed by the robot position, whether it just moved,
the claims and every open label's hit/miss counts, so beliefs are memoised by that key. A look
has one outcome per combination of the open labels' detections (2 ** open labels, see
`MultiLabelBelief.outcomes`), so the tree grows fast: feasible for two or three labels over a
few cones and a short horizon (2 labels x 3 cones x 6 steps: about 0.4 s).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from avs_planner.dt.domain import ActionKind
from avs_planner.dt.errors import DtInputError
from avs_planner.dt.multi.belief import MultiLabelBelief
from avs_planner.dt.multi.domain import MultiAction, MultiObservation
from avs_planner.dt.multi.models import valid_actions
from avs_planner.dt.multi.problem import MultiLabelProblem

MultiBeliefPolicy = Callable[[MultiLabelBelief, int], MultiAction]


@dataclass(frozen=True)
class MultiExactSolution:
    """Optimal expected reward (minus expected cost) and first action for a belief."""

    value: float
    action: MultiAction
    beliefs_solved: int


def outcomes(problem: MultiLabelProblem, belief: MultiLabelBelief,
             action: MultiAction) -> list[tuple[float, MultiLabelBelief]]:
    """(probability, next belief) for each observation `action` can produce."""
    return belief.outcomes(action, problem)


def immediate_reward(problem: MultiLabelProblem, belief: MultiLabelBelief,
                     action: MultiAction) -> float:
    """Expected reward of `action` under `belief` (shared costs, one label's penalty)."""
    kind = action.kind
    if kind is ActionKind.MOVE:
        return -problem.travel_cost(belief.robot, action.cone)
    if kind is ActionKind.PROCESS_VIEW_CONE:
        return -problem.sensing_cost
    i = problem.index(action.label)
    rewards = problem.single(i).rewards
    if kind is ActionKind.CONFIRM:
        return -rewards.false_confirm_penalty * (1.0 - belief.probs(i)[action.cone])
    return -rewards.miss_penalty * belief.factors[i].p_present


def _actions(problem: MultiLabelProblem, belief: MultiLabelBelief,
             steps_left: int) -> list[MultiAction]:
    detected = tuple(f.detected for f in belief.factors)
    actions = valid_actions(problem, belief.robot, detected, belief.claims,
                            belief.after_move and steps_left > 0)
    if steps_left <= 0:
        return [a for a in actions if a.terminal]
    return actions


class MultiExactSolver:
    """Optimal values over the belief tree with at most `steps_left` MOVE/PROCESS actions
    (CONFIRM/REJECT take no step)."""

    def __init__(self, problem: MultiLabelProblem, max_beliefs: int = 2_000_000):
        self.problem = problem
        self.max_beliefs = max_beliefs
        self._memo: dict[tuple, tuple[float, MultiAction | None]] = {}

    def solve(self, belief: MultiLabelBelief, steps_left: int) -> MultiExactSolution:
        """Optimal value and action; DtInputError if the tree exceeds `max_beliefs` or the
        search is already finished."""
        if belief.finished(self.problem):
            raise DtInputError("exact solver: the search is already finished")
        value, action = self._value(belief, steps_left)
        return MultiExactSolution(value, action, len(self._memo))

    def _value(self, belief: MultiLabelBelief, steps_left: int
               ) -> tuple[float, MultiAction | None]:
        if belief.finished(self.problem):
            return 0.0, None
        key = (belief.key, steps_left)
        cached = self._memo.get(key)
        if cached is not None:
            return cached
        if len(self._memo) >= self.max_beliefs:
            raise DtInputError(f"exact solver: more than {self.max_beliefs} beliefs; "
                               "the instance is too large for exact solution")
        best = max(((self._q(belief, a, steps_left), a)
                    for a in _actions(self.problem, belief, steps_left)),
                   key=lambda qa: qa[0])
        self._memo[key] = best
        return best

    def _q(self, belief: MultiLabelBelief, action: MultiAction, steps_left: int) -> float:
        reward = immediate_reward(self.problem, belief, action)
        left = steps_left if action.terminal else steps_left - 1
        return reward + sum(p * self._value(nxt, left)[0]
                            for p, nxt in outcomes(self.problem, belief, action))


def evaluate_multi_policy(problem: MultiLabelProblem, policy: MultiBeliefPolicy,
                          belief: MultiLabelBelief, steps_left: int) -> float:
    """Exact expected reward of a deterministic policy of (belief, steps_left), by enumerating
    observations; with no steps left it may only CONFIRM/REJECT, as in a session."""
    memo: dict[tuple, float] = {}

    def value(b: MultiLabelBelief, k: int) -> float:
        if b.finished(problem):
            return 0.0
        key = (b.key, k)
        if key not in memo:
            action = policy(b, k)
            if k <= 0 and not action.terminal:
                raise DtInputError(f"policy chose {action} with no steps left")
            left = k if action.terminal else k - 1
            memo[key] = immediate_reward(problem, b, action) + sum(
                p * value(nxt, left) for p, nxt in outcomes(problem, b, action))
        return memo[key]

    return value(belief, steps_left)


class MultiExactPolicy:
    """Optimal finite-horizon decisions (small instances only)."""

    name = "exact"

    def __init__(self, problem: MultiLabelProblem, max_beliefs: int = 2_000_000):
        self.solver = MultiExactSolver(problem, max_beliefs)

    def decide(self, belief: MultiLabelBelief, steps_left: int) -> MultiAction:
        return self.solver.solve(belief, steps_left).action

    def observe(self, action: MultiAction, observation: MultiObservation) -> None:
        """Stateless: the memo is keyed by belief."""
