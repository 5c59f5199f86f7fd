"""POUCT for view-cone search: pomdp-py's POUCT with route-aware leaves and a hard horizon.

pomdp-py runs the tree (UCB1, node statistics, tree reuse). The hooks are ours:
- a simulation stops at CONFIRM/REJECT (pomdp-py has no terminal states) and at the step
  budget, where the best stop action is forced;
- leaves are valued by the cheapest route-aware look sequence (`avs_planner.dt.route`, exact
  expected cost under the leaf's belief), new actions start from the same values;
- backups are exact over observations and take each child's best action (the sampled
  running mean was noisy and undervalued looking again).
With `route_leaves=False` the leaves are sampled greedy p/cost rollouts, as before.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import pomdp_py
from pomdp_py.algorithms.po_uct import QNode

from avs_planner.dt.agent import ViewConeAgent
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    ActionKind,
    DTAction,
    DTObservation,
)
from avs_planner.dt.greedy import LOOKAHEAD, look_then_stop_cost, stop_choice, top_cones
from avs_planner.dt.models import ViewConePolicyModel, valid_actions
from avs_planner.dt.problem import DTProblem
from avs_planner.dt.rollout import (
    belief_after_history,
    expected_terminal_reward,
    greedy_rollout_return,
    terminal_reward,
)
from avs_planner.dt.route import best_sequence, route_value

TERMINAL_VISITS = 1_000_000  # CONFIRM/REJECT values are exact: never worth exploring


@dataclass(frozen=True)
class SearchBudget:
    """Planning budget per decision: simulations (deterministic with a seed) or seconds."""

    num_sims: int = 50  # with exact observation averaging and route leaves, 50 matched 200
    planning_time: float = -1.0  # > 0 and num_sims <= 0: plan for this many seconds
    exploration_const: float = 0.0  # 0: 0.13 x the larger terminal penalty
    max_moves: int = 6  # MOVE branches per tree node: best P/cost cones (0: all)
    prior_visits: int = 1  # pseudo-visits given to the greedy lookahead value of a new action
    tree_depth: int = 2  # looks in the tree below the root; deeper is valued by rollouts
    max_backup: bool = True  # a node returns its best action's value to its parent, not the
    # sampled return (mean backups of exploring simulations undervalue looking again)
    route_looks: int = 16  # at most this many looks in a leaf's sequence (0: 2 per cone + 2)
    expected_backup: bool = True  # Q = r + exact expectation over observations of the
    # children's best values (needs route_leaves); False: pomdp-py's sampled running mean
    route_leaves: bool = True  # leaves valued by route-aware look sequences (exact expected
    # cost, `avs_planner.dt.route`); False: by sampled greedy p/cost rollouts


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
            exploration_const=budget.exploration_const or 0.13 * max(penalty, 1.0),
            rollout_policy=ViewConePolicyModel(problem, rng),
        )
        self._problem = problem
        self._rng = rng
        self._steps_left = steps_left
        self._max_moves = budget.max_moves
        self._prior_visits = budget.prior_visits
        self._tree_depth = budget.tree_depth or steps_left
        self._route = budget.route_leaves
        self._max_backup = budget.max_backup
        self._route_looks = budget.route_looks
        self._expected_backup = budget.expected_backup and budget.route_leaves
        self._leaf_values: dict[tuple, float] = {}
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
        belief = self._node_belief(history)  # its `after_move` holds even for a fresh agent
        actions = valid_actions(self._problem, belief.robot, belief.detected, belief.done,
                                belief.after_move)
        if self._max_moves > 0 and len(actions) > self._max_moves + 3:
            keep = set(top_cones(self._problem, belief.robot, belief.probs, self._max_moves))
            actions = [a for a in actions if a.kind is not ActionKind.MOVE or a.cone in keep]
        steps_left = self._steps_left - (len(history) - self._root_len)
        second = 2 if len(history) == self._root_len else 0  # branch wider at the root only
        for action in actions:
            if vnode[action] is None:
                visits, value = self._action_prior(belief, action, steps_left, second)
                vnode[action] = QNode(visits, value)

    def _action_prior(self, belief: TargetBelief, action, steps_left: int,
                      second: int = 2) -> tuple[int, float]:
        """(pseudo-visits, initial value) of a new tree action. CONFIRM/REJECT values are exact
        (expected penalty under the node's belief), so they never need simulating; MOVE and
        PROCESSVIEWCONE start at an achievable value weighted like `prior_visits` simulations:
        the best route-aware look sequence starting there (with `route_leaves`; `second`
        next looks tried after the first, see `best_sequence`), else the
        greedy plan "look there up to LOOKAHEAD times, then stop"."""
        if action.terminal:
            return TERMINAL_VISITS, expected_terminal_reward(self._problem, belief, action)
        if self._prior_visits <= 0:
            return 0, 0.0
        moving = 1 if action.kind is ActionKind.MOVE else 0
        if self._route and steps_left - moving >= 1:
            sequence = best_sequence(self._problem, belief.robot, belief.probs, steps_left,
                                     second=second, forced_first=action.cone,
                                     max_looks=self._route_looks)
            if sequence is not None:
                return self._prior_visits, -sequence.cost
        looks = min(LOOKAHEAD, steps_left - moving)
        if looks < 1:
            return self._prior_visits, -stop_choice(self._problem, belief.robot, belief.detected,
                                                    belief.probs)[0]
        return self._prior_visits, -look_then_stop_cost(self._problem, belief.robot, action.cone,
                                                        belief.probs, looks)

    def _simulate(self, state, history, root, parent, observation, depth):
        if state.done:
            return self._terminal_correction(state, history)
        value = self._simulate_node(state, history, root, parent, observation, depth)
        if self._expected_backup and parent is not None:
            return self._expected_return(history, parent, depth)
        return value

    def _simulate_node(self, state, history, root, parent, observation, depth):
        """One simulation from the node at `history`; returns its value estimate."""
        if depth >= self._steps_left:
            belief = self._node_belief(history)
            return stop_choice(self._problem, belief.robot, belief.detected, belief.probs)[0] * -1
        if self._tree_level(history) >= self._tree_depth:  # below the tree: greedy rollout
            return self._rollout(state, history, None, depth)
        value = super()._simulate(state, history, root, parent, observation, depth)
        if self._max_backup and root is not None:
            visited = [q.value for q in root.children.values() if q.num_visits > 0]
            if visited:
                return max(visited)
        return value

    def _expected_return(self, history: tuple, parent: QNode, depth: int) -> float:
        """What to hand back to the parent so that pomdp-py's running-mean update sets the
        parent's Q to r + sum_o P(o | b, a) V(child_o): the observation is averaged exactly
        under the parent's belief instead of by the sampled frequencies (their noise flipped
        decisions between near-equal actions)."""
        action = history[-1][0]
        above = history[:-1]
        belief = self._node_belief(above)
        if action.kind is ActionKind.MOVE:
            reward, branches = -self._problem.travel_cost(belief.robot, action.cone), [(1.0,
                                                                                       NOTHING)]
        else:
            hit = belief.p_detect(action.cone, self._problem.detector)
            reward = -self._problem.sensing_cost
            branches = [(hit, DETECTED), (1.0 - hit, NOT_DETECTED)]
        expected = reward
        for p, obs in branches:
            if p > 0.0:
                expected += p * self._branch_value(parent[obs], above + ((action, obs),),
                                                   self._steps_left - depth)
        visits = parent.num_visits + 1  # pomdp-py counts this simulation before averaging
        return parent.value + visits * (expected - parent.value) - reward

    def _branch_value(self, vnode, history: tuple, steps_left: int) -> float:
        """Best value known at a child node: its best visited action, else its leaf value."""
        belief = self._node_belief(history)
        if steps_left <= 0:
            return -stop_choice(self._problem, belief.robot, belief.detected, belief.probs)[0]
        if vnode is not None:
            visited = [q.value for q in vnode.children.values() if q.num_visits > 0]
            if visited:
                return max(visited)
        return self._route_leaf_value(belief, steps_left)

    def _tree_level(self, history: tuple) -> int:
        """Decisions below the root, not counting MOVEs: a MOVE's only continuation is the
        look there, so counting it would give moves a shallower (less diluted) subtree than
        looking again, biasing the tree toward moving."""
        return sum(1 for action, _ in history[self._root_len:]
                   if action.kind is not ActionKind.MOVE)

    def _terminal_correction(self, state, history) -> float:
        """Swap the sampled CONFIRM/REJECT penalty (already added by pomdp-py) for its
        expectation under the belief at that node: same mean, far less variance."""
        action = history[-1][0]
        belief = self._node_belief(history[:-1])
        return expected_terminal_reward(self._problem, belief, action) - terminal_reward(
            self._problem, state, action)

    def _rollout(self, state, history, root, depth):
        belief = self._node_belief(history)
        if self._route:
            return self._route_leaf_value(belief, self._steps_left - depth)
        return greedy_rollout_return(self._problem, state, belief, self._steps_left - depth,
                                     self._rng)

    def _route_leaf_value(self, belief: TargetBelief, steps_left: int) -> float:
        """Value of the better of stopping and the best route-aware look sequence (exact
        expectation under the node's belief, memoised per belief)."""
        key = (belief.key, steps_left)
        value = self._leaf_values.get(key)
        if value is None:
            stop = stop_choice(self._problem, belief.robot, belief.detected, belief.probs)[0]
            value = -route_value(self._problem, belief.robot, belief.probs, belief.after_move,
                                 steps_left, stop, self._route_looks)
            self._leaf_values[key] = value
        return value


class POUCTPolicy:
    """pomdp-py POUCT over the agent's histogram belief, reusing the search tree."""

    name = "pouct"

    def __init__(self, problem: DTProblem, seed: int = 0, budget: SearchBudget | None = None):
        self.problem = problem
        self._rng = random.Random(seed)
        self._budget = budget or SearchBudget()
        self.agent = ViewConeAgent(problem, self._rng)
        self._planner: ViewConePOUCT | None = None
        self.last_num_sims = 0

    def decide(self, belief: TargetBelief, steps_left: int) -> DTAction:
        self._planner = ViewConePOUCT(self.problem, self._rng, steps_left, self._budget)
        action = self._planner.plan_from(self.agent, belief)
        self.last_num_sims = self._planner.last_num_sims
        return action

    def observe(self, action: DTAction, observation: DTObservation) -> None:
        self.agent.update(action, observation)
        if self._planner is not None and getattr(self.agent, "tree", None) is not None:
            self._planner.update(self.agent, action, observation)


def pouct_decision_rule(problem: DTProblem, seed: int = 0, budget: SearchBudget | None = None):
    """POUCT as a deterministic function of (belief, steps_left): a fresh search per decision,
    seeded by the belief. Without tree reuse it is slightly weaker than `POUCTPolicy`, but
    `evaluate_policy` can compute its exact expected cost (no Monte Carlo noise)."""
    budget = budget or SearchBudget()

    def decide(belief: TargetBelief, steps_left: int) -> DTAction:
        if steps_left <= 0:  # as in a session: only the best stop is left
            return stop_choice(problem, belief.robot, belief.detected, belief.probs)[1]
        rng = random.Random(hash((seed, belief.key, steps_left)))
        agent = ViewConeAgent(problem, rng, belief)
        return ViewConePOUCT(problem, rng, steps_left, budget).plan_from(agent, belief)

    return decide
