"""Baseline decision rules with the same interface as the POMDP planners.

`GreedyPolicy`: highest probability per cost next, stop when one more look does not pay.
`SweepPolicy`: a fixed nearest-neighbour tour over the cones, each looked at once; confirm at
the first detection, reject after the tour.
"""

from __future__ import annotations

from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import START, DTAction, DTObservation, confirm, look, move
from avs_planner.dt.greedy import greedy_action, stop_choice
from avs_planner.dt.problem import DTProblem


class GreedyPolicy:
    """Greedy p/cost with a one-step-lookahead stopping rule (see `avs_planner.dt.greedy`)."""

    name = "greedy"

    def __init__(self, problem: DTProblem):
        self.problem = problem

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction:
        return greedy_action(self.problem, belief.robot, belief.detected, belief.probs,
                             belief.after_move, steps_left)

    def observe(self, action: DTAction, observation: DTObservation) -> None:
        """Stateless: everything it needs is in the belief."""


def nearest_neighbour_tour(problem: DTProblem) -> tuple[int, ...]:
    """Order of the relevant cones: always the cheapest unvisited one next, from the start."""
    left, order, here = set(problem.relevant_cones), [], START
    while left:
        here = min(sorted(left), key=lambda c: problem.travel_cost(here, c))
        order.append(here)
        left.discard(here)
    return tuple(order)


class SweepPolicy:
    """Visit every cone once in a fixed tour; confirm at the first detection."""

    name = "sweep"

    def __init__(self, problem: DTProblem):
        self.problem = problem
        self.tour = nearest_neighbour_tour(problem)

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction:
        if belief.detected and belief.robot != START:
            return confirm(belief.robot)
        if belief.after_move and steps_left >= 1:
            return look(belief.robot)
        unseen = [c for c in self.tour if belief.hits[c] + belief.misses[c] == 0]
        if not unseen or steps_left < 2:
            return stop_choice(self.problem, belief.robot, belief.detected, belief.probs)[1]
        return move(unseen[0]) if unseen[0] != belief.robot else look(unseen[0])

    def observe(self, action: DTAction, observation: DTObservation) -> None:
        """Stateless: the look counts in the belief say which cones were swept."""


