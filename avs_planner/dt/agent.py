"""The DT agent: the pomdp-py models plus a histogram belief over `DTState`.

The belief is updated exactly with `pomdp_py.update_histogram_belief`; with the robot position
and detection flag observed it has at most `n + 1` entries, so exact updates stay cheap even at
tens of cones.
"""

from __future__ import annotations

import random

import pomdp_py

from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import DTAction, DTObservation, DTState
from avs_planner.dt.errors import DtSessionError
from avs_planner.dt.models import (
    ViewConeObservationModel,
    ViewConePolicyModel,
    ViewConeRewardModel,
    ViewConeTransitionModel,
)
from avs_planner.dt.problem import DTProblem


class ViewConeAgent(pomdp_py.Agent):
    """pomdp-py agent for one view-cone search; samples its belief with its own seeded RNG."""

    def __init__(self, problem: DTProblem, rng: random.Random,
                 belief: TargetBelief | None = None):
        start = belief if belief is not None else TargetBelief.initial(problem)
        super().__init__(
            start.to_histogram(),
            ViewConePolicyModel(problem, rng),
            ViewConeTransitionModel(problem, rng),
            ViewConeObservationModel(),
            ViewConeRewardModel(problem),
            name="view-cone-search",
        )
        self.problem = problem
        self._rng = rng

    def sample_belief(self) -> DTState:
        return self.belief.random(rnd=self._rng)

    def update(self, real_action: DTAction, real_observation: DTObservation) -> None:
        """Record (action, observation) and update the histogram belief exactly."""
        self.update_history(real_action, real_observation)
        updated = pomdp_py.update_histogram_belief(
            self.belief, real_action, real_observation,
            self.observation_model, self.transition_model,
            next_state_space=self._successor_support(real_action),
        )
        support = {s: p for s, p in updated.histogram.items() if p > 0.0}
        if not support:
            raise DtSessionError(
                f"observation {real_observation.kind.value} after {real_action} is impossible "
                "under the agent's model")
        self.set_belief(pomdp_py.Histogram(support))

    def _successor_support(self, action: DTAction) -> set[DTState]:
        model: ViewConeTransitionModel = self.transition_model
        return {s for state in self.belief for s, _ in model.successors(state, action)}
