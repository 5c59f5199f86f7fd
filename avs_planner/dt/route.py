"""Route-aware look sequences: expected search cost of looking at cones in an order (FLAP,
seed 000, eq. 4-6), built by the utility-greedy rule p / t from a few different first looks.

A sequence is open-loop on misses: look at its cones in order (a cone may repeat: a second
look after a miss); at the first detection stop as well as possible (confirm, reject, or look
there again up to twice, then stop); after the sequence's best prefix, reject. A miss only
rescales the belief, so one pass computes the expected cost exactly, without sampling. POUCT
uses the best sequence's cost as the value of its tree leaves: the greedy p/cost rollout
cannot see that a low-probability cone on the way to a likely one is worth a look first.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from avs_planner.dt.domain import START
from avs_planner.dt.greedy import looks_then_stop_cost
from avs_planner.dt.problem import DTProblem

CONFIRM_LOOKS = 2  # extra looks considered after a detection before confirming or rejecting


@dataclass(frozen=True)
class LookSequence:
    """Cones to look at in order (best prefix only) and its expected cost incl. penalties."""

    cones: tuple[int, ...]
    cost: float


def detected_cost(problem: DTProblem, p: float, p_none: float, steps_left: float) -> float:
    """Cheapest expected cost right after a detection at a cone with posterior `p` (nowhere:
    `p_none`): confirm, reject, or look again 1..CONFIRM_LOOKS times and then stop."""
    rewards = problem.rewards
    best = min(rewards.false_confirm_penalty * (1.0 - p), rewards.miss_penalty * (1.0 - p_none))
    for looks in range(1, int(min(CONFIRM_LOOKS, steps_left)) + 1):
        best = min(best, looks_then_stop_cost(problem, p, p_none, looks))
    return best


def sequence_cost(problem: DTProblem, robot: int, probs: Sequence[float],
                  cones: Sequence[int], steps_left: float = math.inf) -> tuple[float, int]:
    """(expected cost, looks) of the best prefix (at least one look) of `cones` from `robot`
    under `probs`; a MOVE and a look count as two steps against `steps_left`."""
    hit_in, hit_out = problem.detection_rates
    in_ratio = (1.0 - hit_in) / (1.0 - hit_out)
    miss_penalty, sensing = problem.rewards.miss_penalty, problem.sensing_cost
    q = list(probs)  # joint P(target, all looks so far missed) = scale * q
    scale, alive, spent = 1.0, 1.0, 0.0
    best, best_len, here = math.inf, 0, robot
    for i, cone in enumerate(cones):
        steps_left -= 1 if cone == here else 2
        if steps_left < 0:
            break
        spent += alive * (problem.travel_cost(here, cone) + sensing)
        q_cone = q[cone] * scale
        found = q_cone * hit_in
        detect = found + (alive - q_cone) * hit_out
        if detect > 0.0:
            spent += detect * detected_cost(problem, found / detect,
                                            q[-1] * scale * hit_out / detect, steps_left)
        alive -= detect
        q[cone] *= in_ratio
        scale *= 1.0 - hit_out
        total = spent + miss_penalty * (alive - q[-1] * scale)
        if total < best:
            best, best_len = total, i + 1
        here = cone
    return best, best_len


def utility_sequence(problem: DTProblem, robot: int, probs: Sequence[float], first: int,
                     length: int) -> list[int]:
    """`first`, then `length - 1` looks each chosen by the highest utility P(detect) / cost
    (FLAP eq. 6) from where the previous look was, with the belief after misses."""
    hit_in, hit_out = problem.detection_rates
    in_ratio = (1.0 - hit_in) / (1.0 - hit_out)
    q = list(probs)  # proportional to the real belief: ratios are all the utility needs
    cones, here = [first], first
    q[first] *= in_ratio
    for _ in range(length - 1):
        best, best_util = -1, 0.0
        for cone, inverse_cost in problem.look_weights[here]:
            util = q[cone] * inverse_cost
            if util > best_util:
                best, best_util = cone, util
        if best < 0:
            break
        cones.append(best)
        q[best] *= in_ratio
        here = best
    return cones


def first_looks(problem: DTProblem, robot: int, probs: Sequence[float], count: int) -> list[int]:
    """The `count` cones with the highest utility from `robot` (candidates for the first look)."""
    scored = sorted(((probs[c] * w, -c) for c, w in problem.look_weights[robot]), reverse=True)
    return [-neg for util, neg in scored[:count] if util > 0.0]


def best_sequence(problem: DTProblem, robot: int, probs: Sequence[float],
                  steps_left: float = math.inf, branches: int = 3,
                  forced_first: int | None = None) -> LookSequence | None:
    """Cheapest utility-greedy sequence over `branches` first looks (or `forced_first`, e.g.
    the cone the robot just moved to); None if no look is possible."""
    length = int(min(steps_left, 2 * len(problem.relevant_cones) + 2))
    if forced_first is not None:
        starts = [forced_first]
    else:
        starts = first_looks(problem, robot, probs, branches)
    best: LookSequence | None = None
    for first in starts:
        cones = utility_sequence(problem, robot, probs, first, length)
        cost, looks = sequence_cost(problem, robot, probs, cones, steps_left)
        if looks and (best is None or cost < best.cost):
            best = LookSequence(tuple(cones[:looks]), cost)
    return best


def route_value(problem: DTProblem, robot: int, probs: Sequence[float], after_move: bool,
                steps_left: float, stop_cost: float) -> float:
    """Expected cost of the better of stopping now (`stop_cost`) and the best look sequence;
    right after a MOVE the robot must look where it is first."""
    forced = robot if after_move and robot != START else None
    sequence = best_sequence(problem, robot, probs, steps_left, forced_first=forced)
    if sequence is None:
        return stop_cost
    return sequence.cost if after_move else min(stop_cost, sequence.cost)
