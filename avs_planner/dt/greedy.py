"""The greedy rule: look next where probability per cost is highest; stop when looking there up
to `LOOKAHEAD` more times (then confirming or rejecting) no longer beats stopping now.

Looking several times is part of the lookahead because with false negatives one more look
rarely pays on its own, while two or three often do.

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


LOOKAHEAD = 3


def repeated_look_cost(problem: DTProblem, robot: int, cone: int, probs: Sequence[float],
                       looks: int) -> float:
    """Expected cost of going to `cone`, processing it `looks` times, then stopping as well as
    possible."""
    return problem.travel_cost(robot, cone) + looks_then_stop_cost(problem, probs[cone],
                                                                   probs[-1], looks)


def looks_then_stop_cost(problem: DTProblem, p: float, p_none: float, looks: int) -> float:
    """Expected cost of processing a cone with P(target) `p` `looks` times (P(nowhere) is
    `p_none`), then stopping as well as possible. The belief after the looks depends only on
    the number of hits (and whether the last look hit, which allows CONFIRM), so sequences are
    grouped by that."""
    hit_in, hit_out = problem.detection_rates
    miss, wrong = problem.rewards.miss_penalty, problem.rewards.false_confirm_penalty
    cost = looks * problem.sensing_cost
    for hits in range(looks + 1):
        like_in = hit_in**hits * (1.0 - hit_in) ** (looks - hits)
        like_out = hit_out**hits * (1.0 - hit_out) ** (looks - hits)
        joint_in, joint_none = p * like_in, p_none * like_out
        z = joint_in + (1.0 - p) * like_out  # P(this hit count, one order)
        if z <= 0.0:
            continue
        reject = miss * (z - joint_none)  # z * P(present | outcome) * miss
        last_hit = math.comb(looks - 1, hits - 1) if hits else 0
        last_miss = math.comb(looks - 1, hits) if hits < looks else 0
        cost += last_miss * reject + last_hit * min(reject, wrong * (z - joint_in))
    return cost


def look_then_stop_cost(problem: DTProblem, robot: int, cone: int,
                        probs: Sequence[float], max_looks: int = LOOKAHEAD) -> float:
    """Best expected cost of looking at `cone` 1..`max_looks` times and then stopping."""
    return min(repeated_look_cost(problem, robot, cone, probs, k)
               for k in range(1, max(1, max_looks) + 1))


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
        moving = 0 if cone == robot else 1
        cost = look_then_stop_cost(problem, robot, cone, probs,
                                   min(LOOKAHEAD, int(min(steps_left, 99)) - moving))
        if cost < best_cost - _EPS:
            best_cone, best_cost = cone, cost
    if best_cone < 0:
        return stop_action
    return look(robot) if best_cone == robot else move(best_cone)
