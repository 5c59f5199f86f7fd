"""POUCT for view-cone search: pomdp-py's POUCT with greedy rollouts and a hard horizon.

pomdp-py runs the tree (UCB1, node statistics, tree reuse). Two hooks are ours: a simulation
stops at CONFIRM/REJECT (pomdp-py has no terminal states) and at the step budget, where the
best stop action is forced; and the rollout is the greedy policy run in a tight loop
(pomdp-py's generic rollout would step the models until `max_depth` even after the episode
ended).
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import pomdp_py
from pomdp_py.algorithms.po_uct import QNode

from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import ActionKind
from avs_planner.dt.greedy import stop_choice, top_cones
from avs_planner.dt.models import ViewConePolicyModel
from avs_planner.dt.problem import DTProblem
from avs_planner.dt.rollout import (
    belief_after_history,
    expected_terminal_reward,
    greedy_rollout_return,
    terminal_reward,
)


@dataclass(frozen=True)
class SearchBudget:
    """Planning budget per decision: simulations (deterministic with a seed) or seconds."""

    num_sims: int = 300
    planning_time: float = -1.0  # > 0 and num_sims <= 0: plan for this many seconds
    exploration_const: float = 0.0  # 0: scale with the terminal penalties
    max_moves: int = 6  # MOVE branches per tree node: best P/cost cones (0: all)


class ViewConePOUCT(pomdp_py.POUCT):
    """POUCT whose simulations end at CONFIRM/REJECT and at `steps_left` actions."""

    def __init__(self, problem: DTProblem, rng: random.Random, steps_left: int,
                 budget: SearchBudget):
        penalty = max(problem.rewards.miss_penalty, problem.rewards.false_confirm_penalty)
        super().__init__(
            max_depth=steps_left,
            num_sims=budget.num_sims,
            planning_time=budget.planning_time,
            discount_factor=1.0,
            exploration_const=budget.exploration_const or 0.5 * max(penalty, 1.0),
            rollout_policy=ViewConePolicyModel(problem, rng),
        )
        self._problem = problem
        self._rng = rng
        self._steps_left = steps_left
        self._max_moves = budget.max_moves
        self._root_belief: TargetBelief | None = None
        self._root_len = 0
        self._beliefs = {}
        self._policy_model: ViewConePolicyModel | None = None

    def plan_from(self, agent: pomdp_py.Agent, belief: TargetBelief):
        """Plan one action for `agent`, whose current belief is `belief` (exact)."""
        self._root_belief = belief
        self._root_len = len(agent.history)
        self._beliefs: dict[tuple, TargetBelief] = {}
        self._policy_model = agent.policy_model
        return self.plan(agent)

    def _node_belief(self, history: tuple) -> TargetBelief:
        """Exact belief at the tree node reached by `history` (memoised per suffix)."""
        suffix = history[self._root_len:]
        belief = self._beliefs.get(suffix)
        if belief is None:
            if not suffix:
                return self._root_belief
            parent = self._node_belief(history[:-1])
            belief = belief_after_history(self._problem, parent, suffix[-1:])
            self._beliefs[suffix] = belief
        return belief

    def _expand_vnode(self, vnode, history, state=None):
        """Add the node's actions; MOVE only to the `max_moves` best cones by P/cost under the
        node's belief (the other moves are kept out of the tree, not out of the model)."""
        actions = self._policy_model.get_all_actions(state=state, history=history)
        if self._max_moves > 0 and len(actions) > self._max_moves + 3:
            belief = self._node_belief(history)
            keep = set(top_cones(self._problem, belief.robot, belief.probs, self._max_moves))
            actions = [a for a in actions if a.kind is not ActionKind.MOVE or a.cone in keep]
        for action in actions:
            if vnode[action] is None:
                vnode[action] = QNode(self.num_visits_init, self.value_init)

    def _simulate(self, state, history, root, parent, observation, depth):
        if state.done:
            return self._terminal_correction(state, history)
        if depth >= self._steps_left:
            belief = self._node_belief(history)
            return stop_choice(self._problem, belief.robot, belief.detected, belief.probs)[0] * -1
        return super()._simulate(state, history, root, parent, observation, depth)

    def _terminal_correction(self, state, history) -> float:
        """Swap the sampled CONFIRM/REJECT penalty (already added by pomdp-py) for its
        expectation under the belief at that node: same mean, far less variance."""
        action = history[-1][0]
        belief = self._node_belief(history[:-1])
        return expected_terminal_reward(self._problem, belief, action) - terminal_reward(
            self._problem, state, action)

    def _rollout(self, state, history, root, depth):
        return greedy_rollout_return(self._problem, state, self._node_belief(history),
                                     self._steps_left - depth, self._rng)
