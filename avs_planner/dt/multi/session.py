"""A closed-loop multi-label DT session: the caller executes actions and reports, per label,
what each look detected.

    session = MultiLabelSession(cones, [LabelTarget("cup", p_cup), LabelTarget("book", p_book)])
    while not session.finished:
        action = session.next_action()
        if action.terminal:          # CONFIRM(label, cone) / REJECT(label): already recorded
            report(action)
            continue
        session.update(action, executor.run(action))   # {label: bool} for looks
    session.result.labels["cup"]     # CONFIRMED (cone, probability) / REJECTED / DROPPED

As in `DTSession`, the session keeps the exact (factored) belief, enforces the step budget
(when it is used up the best CONFIRM/REJECT per label is forced) and records a trace.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Any

from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    START,
    ActionKind,
    DTObservation,
    ObservationKind,
)
from avs_planner.dt.errors import DtSessionError
from avs_planner.dt.inputs import Pose2D, ViewCone
from avs_planner.dt.multi.belief import MultiLabelBelief
from avs_planner.dt.multi.domain import OPEN, MultiAction, MultiObservation, SearchMode
from avs_planner.dt.multi.lookahead import stop_decision
from avs_planner.dt.multi.policies import MultiPolicy, make_multi_policy
from avs_planner.dt.multi.problem import LabelTarget, MultiLabelProblem
from avs_planner.dt.problem import TravelCosts

LabelObservations = Mapping[str, bool | DTObservation]


class LabelStatus(Enum):
    OPEN = "open"  # still searched for
    CONFIRMED = "confirmed"
    REJECTED = "rejected"
    DROPPED = "dropped"  # mode "any": still open when another label was confirmed


@dataclass(frozen=True)
class LabelResult:
    """Where one label stands. `probability`: P(label in the confirmed cone) if CONFIRMED,
    else P(label in any cone) left (the evidence the looks leave for the caller's map)."""

    label: str
    status: LabelStatus
    probability: float
    cone_id: str | None = None
    detection: Any = None


@dataclass(frozen=True)
class MultiStep:
    """One executed action, what it observed, its model cost, every label's belief afterwards
    (P per cone, P(in none) last) and the time taken to decide it."""

    action: MultiAction
    observation: MultiObservation
    cost: float
    beliefs: tuple[tuple[float, ...], ...]
    decision_time_s: float


@dataclass(frozen=True)
class MultiLabelResult:
    """How the session ended: a result per label, the total travel and sensing cost, the trace
    (CONFIRM/REJECT included, at cost 0) and every decision's time."""

    labels: Mapping[str, LabelResult]
    cost: float
    trace: tuple[MultiStep, ...]
    decision_times_s: tuple[float, ...]


class MultiLabelSession:
    """Decide, act, observe, until the search for the labels is finished (mode "all": every
    label confirmed or rejected; mode "any": one confirmed, or every one rejected)."""

    def __init__(self, cones: Sequence[ViewCone], targets: Sequence[LabelTarget],
                 start_pose: Pose2D = (0.0, 0.0, 0.0), *,
                 travel_costs: TravelCosts | None = None, sensing_cost: float = 1.0,
                 mode: SearchMode | str = SearchMode.ALL, horizon: int = 0,
                 policy: str = "lookahead"):
        cones = tuple(cones)
        problem = MultiLabelProblem(cones, tuple(targets),
                                    travel_costs or TravelCosts.from_poses(start_pose, cones),
                                    sensing_cost, mode, horizon)
        self._init(problem, make_multi_policy(policy, problem))

    @classmethod
    def from_problem(cls, problem: MultiLabelProblem,
                     policy: str | MultiPolicy = "lookahead") -> MultiLabelSession:
        """A session for an already built problem, with a policy by name or instance."""
        session = cls.__new__(cls)
        chosen = make_multi_policy(policy, problem) if isinstance(policy, str) else policy
        session._init(problem, chosen)
        return session

    def _init(self, problem: MultiLabelProblem, policy: MultiPolicy) -> None:
        self.problem = problem
        self.policy = policy
        self.belief = MultiLabelBelief.initial(problem)
        self._steps: list[MultiStep] = []
        self._moves_and_looks = 0
        self._pending: tuple[MultiAction, float] | None = None
        self._detections: dict[tuple[int, int], Any] = {}
        self._decision_times: list[float] = []
        self._last: MultiAction | None = None
        self._result: MultiLabelResult | None = None

    @property
    def finished(self) -> bool:
        return self._result is not None

    @property
    def result(self) -> MultiLabelResult | None:
        """The outcome once `finished`, else None (see `label_results` meanwhile)."""
        return self._result

    @property
    def steps_left(self) -> int:
        """MOVE/PROCESSVIEWCONE actions left in the budget (CONFIRM/REJECT take none)."""
        return self.problem.horizon - self._moves_and_looks

    def cone(self, action: MultiAction) -> ViewCone | None:
        """The view cone an action refers to (None for REJECT)."""
        return self.problem.cones[action.cone] if action.cone >= 0 else None

    def next_action(self) -> MultiAction:
        """The action to execute next. A CONFIRM/REJECT takes effect when returned (the caller
        reports it, then asks again); once finished, the last action is returned again."""
        if self._result is not None:
            return self._last
        if self._pending is None:
            self._pending = self._decide()
        action, decision_time = self._pending
        if action.terminal:
            self._pending = None
            self._claim(action, decision_time)
        return action

    def _decide(self) -> tuple[MultiAction, float]:
        if self.steps_left <= 0:
            return stop_decision(self.problem, self.belief)[1], 0.0
        start = time.perf_counter()
        action = self.policy.decide(self.belief, self.steps_left)
        return action, time.perf_counter() - start

    def update(self, action: MultiAction,
               observation: LabelObservations | MultiObservation | None = None,
               detections: Mapping[str, Any] | None = None) -> None:
        """Report that `action` was executed and what it observed: for PROCESSVIEWCONE a
        detection result (bool or DTObservation) for every open label, by label (results for
        labels already decided are ignored). `detections[label]` is kept and returned if that
        label is confirmed in this cone. A CONFIRM/REJECT the caller chose itself is accepted
        too."""
        if self._result is not None:
            raise DtSessionError("the multi-label DT session has finished; start a new one")
        if action.terminal:
            self._pending = None  # a proposal made before this claim no longer holds
            self._claim(action, 0.0)
            return
        seen = self._check(action, observation)
        self._check_labels(detections or {}, "detections")
        pending = self._pending
        decision_time = pending[1] if pending is not None and pending[0] == action else 0.0
        cost = self._cost(action)
        self.policy.observe(action, seen)
        self.belief = self.belief.after(action, seen, self.problem)
        for i, obs in enumerate(seen.per_label):
            if obs.kind is ObservationKind.DETECTED:
                self._detections[(i, action.cone)] = (detections or {}).get(self.problem.labels[i])
        self._moves_and_looks += 1
        self._record(action, seen, cost, decision_time)
        self._pending = None

    def _check(self, action: MultiAction,
               observation: LabelObservations | MultiObservation | None) -> MultiObservation:
        problem = self.problem
        if not 0 <= action.cone < problem.n:
            raise DtSessionError(f"{action}: no view cone with index {action.cone}")
        if self.steps_left <= 0:
            raise DtSessionError("step budget used up; only CONFIRM/REJECT remain")
        if action.kind is ActionKind.MOVE:
            nothing = MultiObservation.nothing(problem.k)
            sensed = (observation.per_label != nothing.per_label
                      if isinstance(observation, MultiObservation) else bool(observation))
            if sensed:
                raise DtSessionError(f"{action} observes nothing, got {observation}")
            return nothing
        if action.cone != self.belief.robot or self.belief.robot == START:
            raise DtSessionError(f"{action}: the robot is at cone {self.belief.robot}")
        if isinstance(observation, MultiObservation):
            return observation
        return self._observation(action, observation or {})

    def _observation(self, action: MultiAction, given: LabelObservations) -> MultiObservation:
        """Per label (problem order) the detection result of a look; decided labels NOTHING."""
        self._check_labels(given, "observation")
        per_label = []
        for i, label in enumerate(self.problem.labels):
            value = given.get(label)
            if self.belief.claims[i] != OPEN:
                per_label.append(NOTHING)
                continue
            if isinstance(value, bool):
                value = DETECTED if value else NOT_DETECTED
            if value is None or value.kind is ObservationKind.NOTHING:
                raise DtSessionError(f"{action} needs a detection result (True/False) for "
                                     f"label {label!r}")
            per_label.append(value)
        return MultiObservation(tuple(per_label))

    def _check_labels(self, given: Mapping[str, Any], what: str) -> None:
        unknown = sorted(set(given) - set(self.problem.labels))
        if unknown:
            raise DtSessionError(f"{what} names unknown label(s) {unknown}; the labels are "
                                 f"{list(self.problem.labels)}")

    def _cost(self, action: MultiAction) -> float:
        if action.kind is ActionKind.MOVE:
            return self.problem.travel_cost(self.belief.robot, action.cone)
        return self.problem.sensing_cost

    def _claim(self, action: MultiAction, decision_time: float) -> None:
        self.belief = self.belief.after(action, None, self.problem)
        self._record(action, MultiObservation.nothing(self.problem.k), 0.0, decision_time)
        self._last = action
        if self.belief.finished(self.problem):
            self._result = MultiLabelResult(
                self.label_results(), sum(s.cost for s in self._steps), tuple(self._steps),
                tuple(self._decision_times))

    def _record(self, action: MultiAction, observation: MultiObservation, cost: float,
                decision_time: float) -> None:
        beliefs = tuple(f.probs for f in self.belief.factors)
        self._steps.append(MultiStep(action, observation, cost, beliefs, decision_time))
        self._decision_times.append(decision_time)

    def label_results(self) -> dict[str, LabelResult]:
        """Every label's current standing (OPEN while searched for)."""
        done = self.belief.finished(self.problem)
        results = {}
        for i, label in enumerate(self.problem.labels):
            claim, factor = self.belief.claims[i], self.belief.factors[i]
            if claim >= 0:
                results[label] = LabelResult(label, LabelStatus.CONFIRMED, factor.probs[claim],
                                             self.problem.cones[claim].id,
                                             self._detections.get((i, claim)))
            else:
                status = (LabelStatus.REJECTED if claim != OPEN
                          else LabelStatus.DROPPED if done else LabelStatus.OPEN)
                results[label] = LabelResult(label, status, factor.p_present)
        return results
