"""Route plans for the multi-label lookahead: the expected cost of looking at cones in an order
chosen on the way, computed exactly under the factored belief in one pass (the multi-label
counterpart of `avs_planner.dt.route`: FLAP's expected search cost, with the single-label
DT's handling of a detection).

A route is open-loop on misses: look at its cones in order. At a detection of a label the
route does what it fixed in advance for that label at that look. Settling routes confirm it,
reject it, or verify with one more look there (confirm on a second hit; after a miss the label
stays open and the route goes on), whichever costs least there, as the single-label route
does; the other kind confirms a convincing detection and ignores the rest (on small, tight
budgets that is often the better plan, so `route_cost` takes the better of the two). After the
route's best prefix every open label is rejected.

The labels are independent given the looks, so per label a running joint mass suffices:
P(label in cone j and still open), and P(not confirmed yet). Mode "all" pays a look while any
label is open; mode "any" while no label is confirmed and one is open, and a label's events
at a look count only if no label before it (in problem order) was confirmed at that look.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from avs_planner.dt.multi.belief import MultiLabelBelief
from avs_planner.dt.multi.domain import SearchMode
from avs_planner.dt.multi.problem import MultiLabelProblem

CONFIRM, REJECT, VERIFY, IGNORE = "confirm", "reject", "verify", "ignore"


@dataclass(frozen=True)
class RoutePlan:
    """The best prefix of a route: expected cost, cones looked at in order, and per look what
    a detection there does to each open label (`CONFIRM`, `REJECT`, `VERIFY` or `IGNORE`, by
    position in `open_labels`)."""

    cost: float
    cones: tuple[int, ...]
    on_detection: tuple[tuple[str, ...], ...]


def route_cost(problem: MultiLabelProblem, belief: MultiLabelBelief,
               open_labels: Sequence[int], first: int, steps_left: float,
               max_looks: int = 16) -> float:
    """Expected cost of the better `best_route`, settling detections or not (infinite if no
    look fits in `steps_left`)."""
    return min(best_route(problem, belief, open_labels, first, steps_left, max_looks,
                          settle).cost for settle in (True, False))


def best_route(problem: MultiLabelProblem, belief: MultiLabelBelief,
               open_labels: Sequence[int], first: int, steps_left: float,
               max_looks: int = 16, settle: bool = True) -> RoutePlan:
    """The best prefix of the route that looks at `first`, then always at the cone with the
    most expected penalty removed per second; `settle`: settle detections (else confirm or
    ignore them). A MOVE and a look count as two steps against
    `steps_left`, and so does a look where a detection is verified (the verifying look)."""
    route = _Route(problem, belief, open_labels, settle)
    cones = problem.relevant_cones(open_labels)
    here, best, looked, actions = belief.robot, RoutePlan(math.inf, (), ()), [], []
    for step in range(int(min(steps_left, max_looks or 2 * len(cones) + 2))):
        cone = first if step == 0 else route.next_cone(cones, here)
        if cone < 0:
            break
        steps_left -= 1 if cone == here else 2
        if steps_left < 0:
            break
        actions.append(route.look(here, cone, can_verify=steps_left >= 1))
        if VERIFY in actions[-1]:  # keep a step for it: the plan then fits in every branch
            steps_left -= 1
        looked.append(cone)
        cost = route.end_cost()
        if cost < best.cost:
            best = RoutePlan(cost, tuple(looked), tuple(actions))
        here = cone
    return best


class _Route:
    """The running expectation along a route. Per label: `mass` is the joint P(label in cone
    j, still open), stored divided by `scale` so that a look changes one entry; `open` is its
    sum, `unconfirmed` P(not confirmed yet) (open or rejected); `spent` the expected cost so
    far."""

    def __init__(self, problem: MultiLabelProblem, belief: MultiLabelBelief,
                 open_labels: Sequence[int], settle: bool):
        self.settle = settle
        singles = [problem.single(i) for i in open_labels]
        self.problem = problem
        self.any_mode = problem.mode is SearchMode.ANY
        self.rates = [s.detection_rates for s in singles]
        self.miss = [s.rewards.miss_penalty for s in singles]
        self.wrong = [s.rewards.false_confirm_penalty for s in singles]
        self.mass = [list(belief.probs(i)) for i in open_labels]
        self.scale = [1.0] * len(singles)
        self.open = [sum(m) for m in self.mass]
        self.unconfirmed = list(self.open)
        self.spent = 0.0

    def going(self) -> float:
        """P(the search is still on)."""
        if self.any_mode:  # no label confirmed, and not every label rejected
            return math.prod(self.unconfirmed) - math.prod(
                u - o for u, o in zip(self.unconfirmed, self.open, strict=True))
        return 1.0 - math.prod(1.0 - o for o in self.open)

    def look(self, here: int, cone: int, can_verify: bool) -> tuple[str, ...]:
        """Pay for (moving to and) looking at `cone`; returns what a detection does per label."""
        problem = self.problem
        self.spent += self.going() * (problem.travel_cost(here, cone) + problem.sensing_cost)
        before = list(self.unconfirmed)
        actions = []
        for j in range(len(self.rates)):
            weight = 1.0
            if self.any_mode:  # label j's events count if no label confirmed before it
                weight = math.prod(self.unconfirmed[:j]) * math.prod(before[j + 1:])
            actions.append(self._detection(j, cone, weight, can_verify))
        return tuple(actions)

    def _detection(self, j: int, cone: int, weight: float, can_verify: bool) -> str:
        """Decide label j's detection branch at `cone`: settling, the cheapest of stopping
        there (confirm or reject) and verifying with one more look, as the single-label route
        does; else confirm if that beats rejecting, and ignore the detection otherwise."""
        a, b = self.rates[j]
        sensing = self.problem.sensing_cost
        m_cone, m_none = self.mass[j][cone] * self.scale[j], self.mass[j][-1] * self.scale[j]
        others = self.open[j] - m_cone
        found, detect = m_cone * a, m_cone * a + others * b
        confirm, reject = self.wrong[j] * (detect - found), self.miss[j] * (detect - m_none * b)
        twice = found * a + others * b * b  # P(hit, hit): confirmed after verifying
        if not self.settle:  # confirm a convincing detection, ignore the others
            if detect <= 0.0 or confirm >= reject:
                return IGNORE
            cost, action = confirm, CONFIRM
        else:
            options = [(confirm, CONFIRM), (reject, REJECT)]
            if can_verify:
                options.append((detect * sensing + self.wrong[j] * (twice - found * a), VERIFY))
            cost, action = min(options)
        self.spent += weight * cost
        if action == VERIFY:
            keep_in, keep_out, confirmed = 1.0 - a * a, 1.0 - b * b, twice
        else:
            keep_in, keep_out = 1.0 - a, 1.0 - b
            confirmed = detect if action == CONFIRM else 0.0
        self.unconfirmed[j] -= confirmed
        self.open[j] = m_cone * keep_in + others * keep_out
        self.mass[j][cone] *= keep_in / keep_out
        self.scale[j] *= keep_out
        return action

    def end_cost(self) -> float:
        """Expected cost if the route ends here and every open label is rejected."""
        total = self.spent
        for j, (miss, open_j) in enumerate(zip(self.miss, self.open, strict=True)):
            present = open_j - self.mass[j][-1] * self.scale[j]
            if self.any_mode:  # only if no other label was confirmed
                present *= math.prod(u for i, u in enumerate(self.unconfirmed) if i != j)
            total += miss * present
        return total

    def next_cone(self, cones: Sequence[int], here: int) -> int:
        """The cone with the most expected penalty removed per second from `here` (-1: none)."""
        gain: list[float] = []
        for miss, (a, _), scale, mass in zip(self.miss, self.rates, self.scale, self.mass,
                                             strict=True):
            w = miss * a * scale  # whole lists per label: this runs at every step of a route
            gain = ([w * q for q in mass] if not gain
                    else [g + w * q for g, q in zip(gain, mass, strict=True)])
        inverse = self.problem.inverse_look_costs[here]
        best, best_utility = -1, 0.0
        for cone in cones:
            utility = gain[cone] * inverse[cone]
            if utility > best_utility:
                best, best_utility = cone, utility
        return best
