"""The greedy rule: look next where probability per cost is highest, stop when a look no longer
pays (one-step lookahead on the terminal penalties).

It is the greedy baseline and the rollout policy of the POUCT planner, so it works on plain
sequences (`probs`: P(target in cone i) for i < n, P(in none) last) for speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from avs_planner.dt.domain import REJECT, DTAction, confirm, look, move
from avs_planner.dt.problem import DTProblem

_EPS = 1e-12


def stop_choice(problem: DTProblem, robot: int, detected: bool,
                probs: Sequence[float]) -> tuple[float, DTAction]:
    """Cheapest way to stop now: (expected penalty, CONFIRM or REJECT)."""
    rewards = problem.rewards
    reject = rewards.miss_penalty * (1.0 - probs[-1])
    if detected and robot >= 0:
        wrong = rewards.false_confirm_penalty * (1.0 - probs[robot])
        if wrong < reject:
            return wrong, confirm(robot)
    return reject, REJECT


def look_then_stop_cost(problem: DTProblem, robot: int, cone: int,
                        probs: Sequence[float]) -> float:
    """Expected cost of going to `cone`, processing it once, then stopping as well as possible."""
    hit_in, hit_out = problem.detection_rates
    miss, wrong = problem.rewards.miss_penalty, problem.rewards.false_confirm_penalty
    p, p_none = probs[cone], probs[-1]
    cost = problem.travel_cost(robot, cone) + problem.sensing_cost
    z = p * hit_in + (1.0 - p) * hit_out  # P(detection)
    if z > 0.0:
        cost += min(miss * (z - p_none * hit_out), wrong * (z - p * hit_in))
    z = 1.0 - z
    if z > 0.0:
        cost += miss * (z - p_none * (1.0 - hit_out))
    return cost


def top_cones(problem: DTProblem, robot: int, probs: Sequence[float], k: int) -> list[int]:
    """The `k` relevant cones with the highest P(target) / (travel + sensing cost)."""
    scored = sorted(((probs[c] * w, -c) for c, w in problem.look_weights[robot]), reverse=True)
    return [-neg for _, neg in scored[:k]]


def best_ratio_cone(problem: DTProblem, robot: int, probs: Sequence[float]) -> int:
    """Relevant cone with the highest P(target) / (travel + sensing cost); -1 if none."""
    best, best_ratio = -1, -1.0
    for cone, inverse_cost in problem.look_weights[robot]:
        ratio = probs[cone] * inverse_cost
        if ratio > best_ratio:
            best, best_ratio = cone, ratio
    return best


def greedy_action(problem: DTProblem, robot: int, detected: bool, probs: Sequence[float],
                  after_move: bool = False, steps_left: float = math.inf) -> DTAction:
    """The greedy decision for one belief; `steps_left` is the remaining action budget."""
    stop_cost, stop_action = stop_choice(problem, robot, detected, probs)
    if steps_left < 1:
        return stop_action
    if after_move:
        return look(robot)
    candidates = {robot} if robot >= 0 else set()
    if steps_left >= 2:
        candidates.add(best_ratio_cone(problem, robot, probs))
    candidates.discard(-1)
    best_cone, best_cost = -1, stop_cost
    for cone in sorted(candidates):
        cost = look_then_stop_cost(problem, robot, cone, probs)
        if cost < best_cost - _EPS:
            best_cone, best_cost = cone, cost
    if best_cone < 0:
        return stop_action
    return look(robot) if best_cone == robot else move(best_cone)
