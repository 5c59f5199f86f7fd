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
from avs_planner.dt.problem import DTProblem


@dataclass(frozen=True)
class LookSequence:
    """Cones to look at in order (best prefix only) and its expected cost incl. penalties."""

    cones: tuple[int, ...]
    cost: float


def detected_cost(problem: DTProblem, p: float, p_none: float, steps_left: float) -> float:
    """Cheapest expected cost right after a detection at a cone with posterior `p` (nowhere:
    `p_none`): confirm, reject, or look again once or twice and then stop. Closed form of
    `min(looks_then_stop_cost(.., k))` for k <= 2 (it runs at every step of every sequence)."""
    miss, wrong = problem.rewards.miss_penalty, problem.rewards.false_confirm_penalty
    best = min(wrong * (1.0 - p), miss * (1.0 - p_none))
    if steps_left < 1:
        return best
    a, b = problem.detection_rates
    p_out, sensing = 1.0 - p, problem.sensing_cost
    # joint P(target in cone | nowhere, outcome) for each hit pattern of up to two looks
    hit_in, hit_none, hit_z = p * a, p_none * b, p * a + p_out * b
    miss_in, miss_none, miss_z = p - hit_in, p_none - hit_none, 1.0 - hit_z

    def stop_hit(z_in: float, z_none: float, z: float) -> float:
        return min(miss * (z - z_none), wrong * (z - z_in))

    best = min(best, sensing + stop_hit(hit_in, hit_none, hit_z) + miss * (miss_z - miss_none))
    if steps_left < 2:
        return best
    two = (2.0 * sensing
           + stop_hit(hit_in * a, hit_none * b, p * a * a + p_out * b * b)  # hit, hit
           + stop_hit(miss_in * a, miss_none * b, p * (1 - a) * a + p_out * (1 - b) * b)
           + miss * (p * a * (1 - a) + p_out * b * (1 - b) - hit_none * (1 - b))  # hit, miss
           + miss * ((p * (1 - a) ** 2 + p_out * (1 - b) ** 2) - miss_none * (1 - b)))
    return min(best, two)


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
