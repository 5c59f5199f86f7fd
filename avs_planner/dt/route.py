"""Route-aware look sequences: expected search cost of looking at cones in an order (FLAP by
Gedicke et al., eq. 4-6), built by the utility-greedy rule p / t from a few different first
looks.

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
    `min(looks_then_stop_cost(.., k))` for k <= 2."""
    return joint_detected_cost(problem, p, p_none, 1.0, steps_left)


def joint_detected_cost(problem: DTProblem, z_in: float, z_none: float, z: float,
                        steps_left: float) -> float:
    """`z * detected_cost(z_in / z, z_none / z)` without the divisions: for a detection branch
    of probability `z` whose joint mass in the cone is `z_in` and nowhere `z_none` (it runs
    at every step of every sequence, so it is written out)."""
    miss, wrong = problem.rewards.miss_penalty, problem.rewards.false_confirm_penalty
    best = min(wrong * (z - z_in), miss * (z - z_none))
    if steps_left < 1:
        return best
    a, b = problem.detection_rates
    z_out, sensing = z - z_in, problem.sensing_cost * z
    h_in, h_none = z_in * a, z_none * b  # one more look hits
    h = h_in + z_out * b
    m_in, m_none = z_in - h_in, z_none - h_none  # ... or misses
    once = (sensing + min(miss * (h - h_none), wrong * (h - h_in))
            + miss * (z - h - m_none))
    best = min(best, once)
    if steps_left < 2:
        return best
    hh, mh = h_in * a + z_out * b * b, m_in * a + z_out * (1 - b) * b
    hm, mm = h_in * (1 - a) + z_out * b * (1 - b), m_in * (1 - a) + z_out * (1 - b) * (1 - b)
    twice = (2.0 * sensing
             + min(miss * (hh - h_none * b), wrong * (hh - h_in * a))  # hit, hit
             + min(miss * (mh - m_none * b), wrong * (mh - m_in * a))  # miss, hit
             + miss * (hm - h_none * (1 - b)) + miss * (mm - m_none * (1 - b)))
    return min(best, twice)


def sequence_cost(problem: DTProblem, robot: int, probs: Sequence[float],
                  cones: Sequence[int], steps_left: float = math.inf) -> tuple[float, int]:
    """(expected cost, looks) of the best prefix (at least one look) of `cones` from `robot`
    under `probs`; a MOVE and a look count as two steps against `steps_left`.

    After a detection the sequence either stops there (confirm or reject) or, when that is
    dearer than one more look and stopping after a second hit (perhaps after a third look),
    verifies with that look: a second hit stops, a miss (a false alarm) carries on with the
    rest of the sequence. That is the same open-loop plan as after a plain miss, so the
    branch merges exactly into the running belief."""
    cost, looks, _ = _walk(problem, robot, probs, cones, len(cones), steps_left)
    return cost, looks


def _walk(problem: DTProblem, robot: int, probs: Sequence[float], prefix: Sequence[int],
          length: int, steps_left: float) -> tuple[float, int, list[int]]:
    """`sequence_cost` of `prefix` continued by the utility rule P(detect) / cost (FLAP eq. 6)
    from where the previous look was, up to `length` looks; also returns the cones looked at.
    One pass: choosing the next look and costing it share the belief."""
    a, b = problem.detection_rates
    miss_penalty, sensing = problem.rewards.miss_penalty, problem.sensing_cost
    weights, known = problem.look_weights, len(prefix)
    q = list(probs)  # joint P(target, search still going) = scale * q
    scale, alive, spent = 1.0, 1.0, 0.0
    best, best_len, here, cones = math.inf, 0, robot, []
    for i in range(length):
        if i < known:
            cone = prefix[i]
        else:
            cone, best_util = -1, 0.0
            for candidate, inverse_cost in weights[here]:
                util = q[candidate] * inverse_cost
                if util > best_util:
                    cone, best_util = candidate, util
            if cone < 0:
                break
        steps_left -= 1 if cone == here else 2
        if steps_left < 0:
            break
        spent += alive * (problem.travel_cost(here, cone) + sensing)
        q_cone, q_none = q[cone] * scale, q[-1] * scale
        others = alive - q_cone
        stop, verify = _detection_costs(problem, q_cone, others, q_none, steps_left)
        if verify < stop:  # continuing: a miss, or a hit then a miss
            spent += verify
            keep_in, keep_out = 1.0 - a * a, 1.0 - b * b
        else:
            spent += stop
            keep_in, keep_out = 1.0 - a, 1.0 - b
        alive = q_cone * keep_in + others * keep_out
        q[cone] *= keep_in / keep_out
        scale *= keep_out
        total = spent + miss_penalty * (alive - q[-1] * scale)
        if total < best:
            best, best_len = total, i + 1
        here = cone
        cones.append(cone)
    return best, best_len, cones


def _detection_costs(problem: DTProblem, q_cone: float, others: float, q_none: float,
                     steps_left: float) -> tuple[float, float]:
    """Joint expected costs of the detection branch of a look at a cone with joint mass
    `q_cone` (`others` elsewhere, `q_none` of it nowhere): (confirm or reject there, verify
    with one more look: its cost plus the best stop, or third look, after a second hit).
    The false alarms that carry on are costed by the rest of the sequence, not here."""
    a, b = problem.detection_rates
    found = q_cone * a
    detect = found + others * b
    if detect <= 0.0:
        return 0.0, math.inf
    stop = joint_detected_cost(problem, found, q_none * b, detect, 0)
    if steps_left < 1:
        return stop, math.inf
    twice = found * a + others * b * b
    verify = detect * problem.sensing_cost + joint_detected_cost(
        problem, found * a, q_none * b * b, twice, min(1, steps_left - 1))
    return stop, verify


def _in_ratio(problem: DTProblem) -> float:
    """How a miss scales the looked-at cone relative to the others."""
    hit_in, hit_out = problem.detection_rates
    return (1.0 - hit_in) / (1.0 - hit_out)


def first_looks(problem: DTProblem, robot: int, probs: Sequence[float], count: int) -> list[int]:
    """The `count` cones with the highest utility from `robot` (candidates for the next look)."""
    scored = sorted(((probs[c] * w, -c) for c, w in problem.look_weights[robot]), reverse=True)
    return [-neg for util, neg in scored[:count] if util > 0.0]


def _prefixes(problem: DTProblem, robot: int, probs: Sequence[float], firsts: Sequence[int],
              second: int) -> list[tuple[int, ...]]:
    """Two-look prefixes: each first look with the `second` best next looks after its miss
    (FLAP's branching to depth 2; deeper looks follow the utility greedily)."""
    if second <= 0:
        return [(first,) for first in firsts]
    prefixes = []
    for first in firsts:
        after = list(probs)
        after[first] *= _in_ratio(problem)
        nexts = first_looks(problem, first, after, second)
        prefixes.extend((first, nxt) for nxt in nexts) if nexts else prefixes.append((first,))
    return prefixes


def best_sequence(problem: DTProblem, robot: int, probs: Sequence[float],
                  steps_left: float = math.inf, branches: int = 3, second: int = 2,
                  forced_first: int | None = None, max_looks: int = 0) -> LookSequence | None:
    """Cheapest utility-greedy sequence over `branches` first looks (or `forced_first`, e.g.
    the cone the robot just moved to), each with `second` second looks, of at most
    `max_looks` looks (0: two per relevant cone, plus two); None if no look is possible."""
    length = int(min(steps_left, max_looks or 2 * len(problem.relevant_cones) + 2))
    if forced_first is not None:
        firsts = [forced_first]
    else:
        firsts = first_looks(problem, robot, probs, branches)
    best: LookSequence | None = None
    for prefix in _prefixes(problem, robot, probs, firsts, second if length > 1 else 0):
        cost, looks, cones = _walk(problem, robot, probs, prefix, length, steps_left)
        if looks and (best is None or cost < best.cost):
            best = LookSequence(tuple(cones[:looks]), cost)
    return best


def route_value(problem: DTProblem, robot: int, probs: Sequence[float], after_move: bool,
                steps_left: float, stop_cost: float, max_looks: int = 0) -> float:
    """Expected cost of the better of stopping now (`stop_cost`) and the best look sequence;
    right after a MOVE the robot must look where it is first."""
    forced = robot if after_move and robot != START else None
    sequence = best_sequence(problem, robot, probs, steps_left, forced_first=forced,
                             max_looks=max_looks)
    if sequence is None:
        return stop_cost
    return sequence.cost if after_move else min(stop_cost, sequence.cost)
