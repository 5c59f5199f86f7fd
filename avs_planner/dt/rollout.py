"""Greedy rollouts for POUCT: the belief a history leads to, and a fast simulated episode.

The rollout policy sees only the belief (never the sampled state's target); the sampled state
is used, as in any rollout, to draw the detections and score the terminal action.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence

from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import NOWHERE, ActionKind, DTAction, DTState
from avs_planner.dt.greedy import greedy_action
from avs_planner.dt.problem import DTProblem


def belief_after_history(problem: DTProblem, start: TargetBelief | None,
                         history: Sequence) -> TargetBelief:
    """Apply the (action, observation) pairs of `history` to `start` (default: the prior)."""
    belief = start if start is not None else TargetBelief.initial(problem)
    for action, observation in history:
        if belief.done:
            break
        belief = belief.after(action, observation, problem.detector)
    return belief


def greedy_for_belief(problem: DTProblem, belief: TargetBelief,
                      steps_left: float = math.inf) -> DTAction:
    """The greedy action for a belief (see `avs_planner.dt.greedy`)."""
    return greedy_action(problem, belief.robot, belief.detected, belief.probs,
                         belief.after_move, steps_left)


def terminal_reward(problem: DTProblem, state: DTState, action: DTAction) -> float:
    """Reward of CONFIRM/REJECT in the (sampled) true state."""
    rewards = problem.rewards
    if action.kind is ActionKind.CONFIRM:
        return 0.0 if state.target == action.cone else -rewards.false_confirm_penalty
    return -rewards.miss_penalty if state.target != NOWHERE else 0.0


def expected_terminal_reward(problem: DTProblem, belief: TargetBelief,
                             action: DTAction) -> float:
    """Expected reward of CONFIRM/REJECT under `belief`."""
    return _expected_stop(problem, belief.probs, action)


def _expected_stop(problem: DTProblem, probs: Sequence[float], action: DTAction) -> float:
    rewards = problem.rewards
    if action.kind is ActionKind.CONFIRM:
        return -rewards.false_confirm_penalty * (1.0 - probs[action.cone])
    return -rewards.miss_penalty * (1.0 - probs[-1])


def greedy_rollout_return(problem: DTProblem, state: DTState, belief: TargetBelief,
                          steps_left: int, rng: random.Random) -> float:
    """Undiscounted return of following the greedy policy from `belief` until it stops (or
    the step budget forces a stop), with detections drawn for the true target of `state`.
    The final CONFIRM/REJECT is scored by its expectation under the rollout's belief (same
    mean as scoring it on `state`, much lower variance)."""
    robot, detected, after_move = belief.robot, belief.detected, belief.after_move
    probs = list(belief.probs)
    hit_in, hit_out = problem.detection_rates
    target, total = state.target, 0.0
    while True:
        action = greedy_action(problem, robot, detected, probs, after_move, steps_left)
        if action.terminal:
            return total + _expected_stop(problem, probs, action)
        steps_left -= 1
        if action.kind is ActionKind.MOVE:
            total -= problem.travel_cost(robot, action.cone)
            robot, detected, after_move = action.cone, False, True
            continue
        total -= problem.sensing_cost
        detected = rng.random() < (hit_in if target == robot else hit_out)
        after_move = False
        _bayes_in_place(probs, robot, detected, problem)


def _bayes_in_place(probs: list[float], cone: int, seen: bool, problem: DTProblem) -> None:
    hit_in, hit_out = problem.detection_rates
    in_cone = hit_in if seen else 1.0 - hit_in
    elsewhere = hit_out if seen else 1.0 - hit_out
    p_cone = probs[cone]
    z = p_cone * in_cone + (1.0 - p_cone) * elsewhere
    if z <= 0.0:  # cannot happen for detections drawn from this same model
        return
    scale = elsewhere / z
    for i in range(len(probs)):
        probs[i] *= scale
    probs[cone] = p_cone * in_cone / z
