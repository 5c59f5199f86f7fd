"""pomdp-py models of the multi-label view-cone search: transition, observation, reward, policy.

As in the single-label models: MOVE is deterministic; PROCESSVIEWCONE samples one detection
flag per open label, each from that label's detector and independently of the others, so the
observation is a read-out of the next state; CONFIRM/REJECT set one label's claim, and the state
is absorbing (`done`) once the search is finished (every label decided, or in mode "any" one
confirmed). Reward: minus the shared travel/sensing cost, minus one label's terminal penalty.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from itertools import product

import pomdp_py

from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    NOWHERE,
    START,
    ActionKind,
)
from avs_planner.dt.multi.belief import MultiLabelBelief
from avs_planner.dt.multi.domain import (
    OPEN,
    MultiAction,
    MultiLabelState,
    MultiObservation,
    confirm_label,
    finished,
    look_at,
    move_to,
    reject_label,
)
from avs_planner.dt.multi.lookahead import MultiLookaheadPolicy
from avs_planner.dt.multi.problem import MultiLabelProblem


def valid_actions(problem: MultiLabelProblem, robot: int, detected: Sequence[bool],
                  claims: Sequence[int], after_move: bool) -> list[MultiAction]:
    """Actions worth considering. After a MOVE only PROCESSVIEWCONE (moving on, or closing a
    label right after a move, is dominated because costs are >= 0; moving on is kept if travel
    costs break the triangle inequality). CONFIRM(label) only where the label was just seen."""
    labels = problem.labels
    if finished(claims, problem.mode):
        return [reject_label(labels[0])]  # no-op in the absorbing state
    open_labels = [i for i, claim in enumerate(claims) if claim == OPEN]
    here = [look_at(robot)] if robot != START else []
    moves = [move_to(c) for c in problem.relevant_cones(open_labels) if c != robot]
    if after_move:
        return here + (moves if not problem.metric else [])
    confirms = ([confirm_label(labels[i], robot) for i in open_labels if detected[i]]
                if robot != START else [])
    return here + moves + confirms + [reject_label(labels[i]) for i in open_labels]


class MultiLabelTransitionModel(pomdp_py.TransitionModel):
    """T(s' | s, a); detections are sampled here, per open label, with its detector's rates."""

    def __init__(self, problem: MultiLabelProblem, rng: random.Random):
        self._problem = problem
        self._rng = rng

    def _hit_rates(self, state: MultiLabelState, cone: int) -> list[float]:
        """P(detection) per label at `cone` (0 for decided labels: they are not looked for)."""
        return [self._problem.single(i).detector.p_detect(state.targets[i] == cone)
                if claim == OPEN else 0.0 for i, claim in enumerate(state.claims)]

    def successors(self, state: MultiLabelState,
                   action: MultiAction) -> list[tuple[MultiLabelState, float]]:
        """All next states with their probabilities."""
        if state.done:
            return [(state, 1.0)]
        if action.kind is ActionKind.MOVE:
            none = (False,) * len(state.targets)
            return [(MultiLabelState(action.cone, state.targets, none, state.claims), 1.0)]
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            rates = self._hit_rates(state, action.cone)
            results = []
            for flags in product((True, False), repeat=len(rates)):
                p = math.prod(r if f else 1.0 - r for r, f in zip(rates, flags, strict=True))
                if p > 0.0:
                    results.append((MultiLabelState(action.cone, state.targets, flags,
                                                    state.claims), p))
            return results
        return [(self._claimed(state, action), 1.0)]

    def _claimed(self, state: MultiLabelState, action: MultiAction) -> MultiLabelState:
        i = self._problem.index(action.label)
        if state.claims[i] != OPEN:
            return state
        claim = action.cone if action.kind is ActionKind.CONFIRM else NOWHERE
        claims = state.claims[:i] + (claim,) + state.claims[i + 1:]
        return MultiLabelState(state.robot, state.targets, state.detected, claims,
                               finished(claims, self._problem.mode))

    def probability(self, next_state, state, action) -> float:
        return sum(p for s, p in self.successors(state, action) if s == next_state)

    def sample(self, state, action) -> MultiLabelState:
        if action.kind is ActionKind.PROCESS_VIEW_CONE and not state.done:
            flags = tuple(self._rng.random() < r for r in self._hit_rates(state, action.cone))
            return MultiLabelState(action.cone, state.targets, flags, state.claims)
        return self.successors(state, action)[0][0]


class MultiLabelObservationModel(pomdp_py.ObservationModel):
    """O(o | s', a): after PROCESSVIEWCONE, each open label's detection flag of s'; NOTHING
    for decided labels and after other actions."""

    def sample(self, next_state, action) -> MultiObservation:
        k = len(next_state.claims)
        if action.kind is not ActionKind.PROCESS_VIEW_CONE or next_state.done:
            return MultiObservation.nothing(k)
        return MultiObservation(tuple(
            NOTHING if claim != OPEN else DETECTED if seen else NOT_DETECTED
            for claim, seen in zip(next_state.claims, next_state.detected, strict=True)))

    def probability(self, observation, next_state, action) -> float:
        return 1.0 if observation == self.sample(next_state, action) else 0.0


class MultiLabelRewardModel(pomdp_py.RewardModel):
    """R(s, a, s') = -(travel or sensing cost) - the claimed label's terminal penalty."""

    def __init__(self, problem: MultiLabelProblem):
        self._problem = problem

    def sample(self, state, action, next_state) -> float:
        if state.done:
            return 0.0
        kind = action.kind
        if kind is ActionKind.MOVE:
            return -self._problem.travel_cost(state.robot, action.cone)
        if kind is ActionKind.PROCESS_VIEW_CONE:
            return -self._problem.sensing_cost
        i = self._problem.index(action.label)
        if state.claims[i] != OPEN:
            return 0.0
        rewards, target = self._problem.single(i).rewards, state.targets[i]
        if kind is ActionKind.CONFIRM:
            return 0.0 if target == action.cone else -rewards.false_confirm_penalty
        return -rewards.miss_penalty if target != NOWHERE else 0.0

    def probability(self, reward, state, action, next_state) -> float:
        return 1.0 if reward == self.sample(state, action, next_state) else 0.0


def belief_after_history(problem: MultiLabelProblem, start: MultiLabelBelief | None,
                         history: Sequence) -> MultiLabelBelief:
    """Apply the (action, observation) pairs of `history` to `start` (default: the prior)."""
    belief = start if start is not None else MultiLabelBelief.initial(problem)
    for action, observation in history:
        if belief.finished(problem):
            break
        belief = belief.after(action, observation, problem)
    return belief


class MultiLabelPolicyModel(pomdp_py.RolloutPolicy):
    """Legal actions for a state and history (see `valid_actions`); rollouts follow the
    lookahead policy on the belief the history leads to from `start` (default: the prior)."""

    def __init__(self, problem: MultiLabelProblem, rng: random.Random,
                 start: MultiLabelBelief | None = None):
        self._problem = problem
        self._rng = rng
        self._start = start
        self._rollout = MultiLookaheadPolicy(problem, depth=0, branches=0)  # rollouts are hot

    def get_all_actions(self, state=None, history: Sequence = ()) -> list[MultiAction]:
        problem = self._problem
        if state is None:
            n, labels = problem.n, problem.labels
            return ([move_to(c) for c in range(n)] + [look_at(c) for c in range(n)]
                    + [confirm_label(x, c) for x in labels for c in range(n)]
                    + [reject_label(x) for x in labels])
        after_move = bool(history) and history[-1][0].kind is ActionKind.MOVE
        return valid_actions(problem, state.robot, state.detected, state.claims, after_move)

    def sample(self, state) -> MultiAction:
        return self._rng.choice(self.get_all_actions(state))

    def rollout(self, state, history=()) -> MultiAction:
        belief = belief_after_history(self._problem, self._start, history)
        if state.done or belief.finished(self._problem):
            return self.get_all_actions(state, history)[0]  # the absorbing state's no-op
        steps = sum(1 for action, _ in history if not action.terminal)
        return self._rollout.decide(belief, self._problem.horizon - steps)
