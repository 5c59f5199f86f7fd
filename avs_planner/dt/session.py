"""A closed-loop DT session: the caller executes actions and reports what it observed.

    session = DTSession(cones, DetectorModel(), start_pose)
    while True:
        action = session.next_action()
        if session.finished:
            break
        session.update(action, executor.run(action))   # a DTObservation / bool for looks
    session.result   # CONFIRMED (with the detection) or REJECTED (remaining probability)

The session keeps the exact belief, enforces the step budget (when it is used up the best of
CONFIRM/REJECT is forced), and records a trace, so the simulator and a real robot drive it
the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Any

from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import (
    NOTHING,
    START,
    ActionKind,
    DTAction,
    DTObservation,
    ObservationKind,
)
from avs_planner.dt.errors import DtSessionError
from avs_planner.dt.greedy import stop_choice
from avs_planner.dt.inputs import DetectorModel, Pose2D, ViewCone
from avs_planner.dt.policies import DTPolicy, PolicyConfig, make_policy, timed_decision
from avs_planner.dt.pouct import SearchBudget
from avs_planner.dt.problem import DTProblem, DTRewards, TravelCosts


class DTStatus(Enum):
    RUNNING = "running"
    CONFIRMED = "confirmed"
    REJECTED = "rejected"


@dataclass(frozen=True)
class DTStep:
    """One executed action, what was observed, its model cost, and the belief afterwards."""

    action: DTAction
    observation: DTObservation
    cost: float
    belief: tuple[float, ...]
    decision_time_s: float


@dataclass(frozen=True)
class DTResult:
    """How the session ended. `probability`: P(target in the confirmed cone) if CONFIRMED,
    P(target in any cone) left if REJECTED."""

    status: DTStatus
    probability: float
    cost: float
    trace: tuple[DTStep, ...]
    cone_id: str | None = None
    detection: Any = None
    final_action: DTAction | None = None
    decision_times_s: tuple[float, ...] = ()


class DTSession:
    """Decide, act, observe, until the target is confirmed in a cone or rejected."""

    def __init__(self, cones: Sequence[ViewCone], detector: DetectorModel | None = None,
                 start_pose: Pose2D = (0.0, 0.0, 0.0), *,
                 travel_costs: TravelCosts | None = None, sensing_cost: float = 1.0,
                 rewards: DTRewards | None = None, horizon: int = 0, policy: str = "pouct",
                 budget: SearchBudget | None = None, seed: int = 0):
        cones = tuple(cones)
        problem = DTProblem(
            cones,
            travel_costs or TravelCosts.from_poses(start_pose, cones),
            detector or DetectorModel(),
            sensing_cost,
            rewards or DTRewards(),
            horizon,
        )
        self._init(problem, make_policy(policy, problem,
                                        PolicyConfig(seed, budget or SearchBudget())))

    @classmethod
    def from_problem(cls, problem: DTProblem, policy: str | DTPolicy = "pouct",
                     config: PolicyConfig | None = None) -> DTSession:
        """A session for an already built problem, with a policy by name or instance."""
        session = cls.__new__(cls)
        chosen = make_policy(policy, problem, config) if isinstance(policy, str) else policy
        session._init(problem, chosen)
        return session

    def _init(self, problem: DTProblem, policy: DTPolicy) -> None:
        self.problem = problem
        self.policy = policy
        self.belief = TargetBelief.initial(problem)
        self._steps: list[DTStep] = []
        self._pending: tuple[DTAction, float] | None = None
        self._detections: dict[int, Any] = {}
        self._result: DTResult | None = None

    @property
    def finished(self) -> bool:
        return self._result is not None

    @property
    def result(self) -> DTResult | None:
        return self._result

    @property
    def steps_left(self) -> int:
        return self.problem.horizon - len(self._steps)

    def cone(self, action: DTAction) -> ViewCone | None:
        """The view cone an action refers to (None for REJECT)."""
        return self.problem.cones[action.cone] if action.cone >= 0 else None

    def next_action(self) -> DTAction:
        """The action to execute next. A CONFIRM/REJECT ends the session (see `result`)."""
        if self._result is not None:
            return self._result.final_action
        if self._pending is None:
            self._pending = self._decide()
        action = self._pending[0]
        if action.terminal:
            self._finish(action, self._pending[1])
        return action

    def _decide(self) -> tuple[DTAction, float]:
        if self.steps_left <= 0:
            belief = self.belief
            return stop_choice(self.problem, belief.robot, belief.detected, belief.probs)[1], 0.0
        return timed_decision(self.policy, self.belief, self.steps_left)

    def update(self, action: DTAction, observation: DTObservation | bool | None = None,
               detection: Any = None) -> None:
        """Report that `action` was executed and what it observed (a bool or DTObservation
        for PROCESSVIEWCONE; `detection` is kept and returned if that cone is confirmed)."""
        if self._result is not None:
            raise DtSessionError("the DT session has finished; start a new one")
        if action.terminal:
            self._finish(action, 0.0)
            return
        observation = self._check(action, observation)
        decision_time = self._pending[1] if self._pending and self._pending[0] == action else 0.0
        cost = self._cost(action)
        self.policy.observe(action, observation)
        self.belief = self.belief.after(action, observation, self.problem.detector)
        if observation.kind is ObservationKind.DETECTED:
            self._detections[action.cone] = detection
        self._steps.append(DTStep(action, observation, cost, self.belief.probs, decision_time))
        self._pending = None

    def _check(self, action: DTAction, observation: DTObservation | bool | None
               ) -> DTObservation:
        if not 0 <= action.cone < self.problem.n:
            raise DtSessionError(f"{action}: no view cone with index {action.cone}")
        if self.steps_left <= 0:
            raise DtSessionError("step budget used up; only CONFIRM/REJECT remain")
        if action.kind is ActionKind.MOVE:
            if observation not in (None, NOTHING):
                raise DtSessionError(f"{action} observes nothing, got {observation}")
            return NOTHING
        if action.cone != self.belief.robot or self.belief.robot == START:
            raise DtSessionError(f"{action}: the robot is at cone {self.belief.robot}")
        if isinstance(observation, bool):
            return DTObservation.of(observation)
        if observation is None or observation.kind is ObservationKind.NOTHING:
            raise DtSessionError(f"{action} needs a detection result (True/False)")
        return observation

    def _cost(self, action: DTAction) -> float:
        if action.kind is ActionKind.MOVE:
            return self.problem.travel_cost(self.belief.robot, action.cone)
        return self.problem.sensing_cost

    def _finish(self, action: DTAction, decision_time: float) -> None:
        if action.kind is ActionKind.CONFIRM:
            if not (self.belief.detected and action.cone == self.belief.robot):
                raise DtSessionError(f"{action}: only the cone just seen with a detection "
                                     "can be confirmed")
            status, probability = DTStatus.CONFIRMED, self.belief.probs[action.cone]
            cone_id = self.problem.cones[action.cone].id
        else:
            status, probability, cone_id = DTStatus.REJECTED, self.belief.p_present, None
        self._result = DTResult(
            status, probability, sum(s.cost for s in self._steps), tuple(self._steps),
            cone_id, self._detections.get(action.cone), action,
            tuple(s.decision_time_s for s in self._steps) + (decision_time,),
        )
