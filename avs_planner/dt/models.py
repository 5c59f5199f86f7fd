"""pomdp-py models of the view-cone search POMDP: transition, observation, reward, policy.

Transition: MOVE is deterministic; PROCESSVIEWCONE samples the detection flag from the detector
model (so the observation is a deterministic read-out of the next state); CONFIRM/REJECT lead to
an absorbing `done` state. Reward: minus travel/sensing cost, minus the terminal penalties.
"""

from __future__ import annotations

import random
from collections.abc import Sequence

import pomdp_py

from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    NOWHERE,
    REJECT,
    START,
    ActionKind,
    DTAction,
    DTObservation,
    DTState,
    confirm,
    look,
    move,
)
from avs_planner.dt.problem import DTProblem
from avs_planner.dt.rollout import belief_after_history, greedy_for_belief


def valid_actions(problem: DTProblem, robot: int, detected: bool, done: bool,
                  after_move: bool) -> list[DTAction]:
    """Actions worth considering. After a MOVE only PROCESSVIEWCONE (moving on or stopping right
    after a move is dominated because costs are >= 0; moving on is kept if travel costs break
    the triangle inequality)."""
    if done:
        return [REJECT]  # no-op in the absorbing state
    here = [look(robot)] if robot != START else []
    moves = [move(c) for c in problem.relevant_cones if c != robot]
    if after_move:
        return here + (moves if not problem.metric else [])
    stops = [confirm(robot)] if detected and robot != START else []
    return here + moves + stops + [REJECT]


class ViewConeTransitionModel(pomdp_py.TransitionModel):
    """T(s' | s, a); detections are sampled here with the detector's FN/FP rates."""

    def __init__(self, problem: DTProblem, rng: random.Random):
        self._problem = problem
        self._rng = rng

    def successors(self, state: DTState, action: DTAction) -> list[tuple[DTState, float]]:
        """All next states with their probabilities."""
        if state.done:
            return [(state, 1.0)]
        if action.kind is ActionKind.MOVE:
            return [(DTState(action.cone, state.target), 1.0)]
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            p = self._problem.detector.p_detect(state.target == action.cone)
            return [(DTState(action.cone, state.target, True), p),
                    (DTState(action.cone, state.target, False), 1.0 - p)]
        return [(DTState(state.robot, state.target, state.detected, True), 1.0)]

    def probability(self, next_state, state, action) -> float:
        return sum(p for s, p in self.successors(state, action) if s == next_state)

    def sample(self, state, action) -> DTState:
        if action.kind is ActionKind.PROCESS_VIEW_CONE and not state.done:
            p = self._problem.detector.p_detect(state.target == action.cone)
            return DTState(action.cone, state.target, self._rng.random() < p)
        return self.successors(state, action)[0][0]

    def get_all_states(self) -> list[DTState]:
        n = self._problem.n
        return [DTState(r, t, d, done) for r in [START, *range(n)] for t in [NOWHERE, *range(n)]
                for d in (False, True) for done in (False, True)]


class ViewConeObservationModel(pomdp_py.ObservationModel):
    """O(o | s', a): PROCESSVIEWCONE reports the detection flag of s'; other actions NOTHING."""

    def sample(self, next_state, action) -> DTObservation:
        if action.kind is not ActionKind.PROCESS_VIEW_CONE or next_state.done:
            return NOTHING
        return DETECTED if next_state.detected else NOT_DETECTED

    def probability(self, observation, next_state, action) -> float:
        return 1.0 if observation == self.sample(next_state, action) else 0.0

    def get_all_observations(self) -> list[DTObservation]:
        return [NOTHING, DETECTED, NOT_DETECTED]


class ViewConeRewardModel(pomdp_py.RewardModel):
    """R(s, a, s') = -(travel or sensing cost) - terminal penalty."""

    def __init__(self, problem: DTProblem):
        self._problem = problem

    def sample(self, state, action, next_state) -> float:
        if state.done:
            return 0.0
        kind = action.kind
        if kind is ActionKind.MOVE:
            return -self._problem.travel_cost(state.robot, action.cone)
        if kind is ActionKind.PROCESS_VIEW_CONE:
            return -self._problem.sensing_cost
        rewards = self._problem.rewards
        if kind is ActionKind.CONFIRM:
            return 0.0 if state.target == action.cone else -rewards.false_confirm_penalty
        return -rewards.miss_penalty if state.target != NOWHERE else 0.0

    def probability(self, reward, state, action, next_state) -> float:
        return 1.0 if reward == self.sample(state, action, next_state) else 0.0


class ViewConePolicyModel(pomdp_py.RolloutPolicy):
    """Legal actions for a state and history (see `valid_actions`); rollouts are greedy."""

    def __init__(self, problem: DTProblem, rng: random.Random):
        self._problem = problem
        self._rng = rng

    def get_all_actions(self, state=None, history: Sequence = ()) -> list[DTAction]:
        if state is None:
            n = self._problem.n
            return ([move(c) for c in range(n)] + [look(c) for c in range(n)]
                    + [confirm(c) for c in range(n)] + [REJECT])
        after_move = bool(history) and history[-1][0].kind is ActionKind.MOVE
        return valid_actions(self._problem, state.robot, state.detected, state.done, after_move)

    def sample(self, state) -> DTAction:
        return self._rng.choice(self.get_all_actions(state))

    def rollout(self, state, history=()) -> DTAction:
        """Greedy p/cost action for the belief reached by `history` from the prior."""
        belief = belief_after_history(self._problem, None, history)
        return greedy_for_belief(self._problem, belief)
