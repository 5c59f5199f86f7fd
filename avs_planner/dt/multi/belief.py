"""The factored belief of a multi-label search: one exact single-label belief per label.

The labels' locations are independent a priori and each look's detections are independent
given the locations, so the posterior stays a product of per-label posteriors: a look updates
every open label's `TargetBelief` by its own detector, a CONFIRM/REJECT closes one label and
touches no other. The joint over `(n + 1) ** k` locations is never built.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

from avs_planner.dt import domain as single
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    NOWHERE,
    START,
    ActionKind,
    DTAction,
)
from avs_planner.dt.errors import DtInputError, DtSessionError
from avs_planner.dt.multi.domain import OPEN, MultiAction, MultiObservation, finished
from avs_planner.dt.multi.problem import MultiLabelProblem


def single_action(action: MultiAction) -> DTAction:
    """The single-label action a multi-label action is, for one label's belief."""
    if action.kind is ActionKind.MOVE:
        return single.move(action.cone)
    if action.kind is ActionKind.PROCESS_VIEW_CONE:
        return single.look(action.cone)
    if action.kind is ActionKind.CONFIRM:
        return single.confirm(action.cone)
    return single.REJECT


@dataclass(frozen=True)
class MultiLabelBelief:
    """Robot position (START), whether the last action was a MOVE, per label its belief and
    its claim (`OPEN`, `NOWHERE` = rejected, or the confirmed cone)."""

    robot: int
    factors: tuple[TargetBelief, ...]
    claims: tuple[int, ...]
    after_move: bool = False

    @classmethod
    def initial(cls, problem: MultiLabelProblem) -> MultiLabelBelief:
        factors = tuple(TargetBelief.initial(p) for p in problem.singles)
        return cls(START, factors, (OPEN,) * problem.k)

    @property
    def open_labels(self) -> tuple[int, ...]:
        return tuple(i for i, claim in enumerate(self.claims) if claim == OPEN)

    def probs(self, label: int) -> tuple[float, ...]:
        """P(label in cone i) for i < n, P(in none) last."""
        return self.factors[label].probs

    def detected(self, label: int) -> bool:
        """Did the last look at the robot's cone detect `label`?"""
        return self.factors[label].detected

    def finished(self, problem: MultiLabelProblem) -> bool:
        return finished(self.claims, problem.mode)

    @property
    def key(self) -> tuple:
        """Exact identity of this belief for planning (look counts, not floats); a decided
        label's belief no longer matters, so only its claim is in the key."""
        return (self.robot, self.after_move, self.claims,
                tuple(f.key if c == OPEN else None for f, c in zip(self.factors, self.claims,
                                                                    strict=True)))

    def after(self, action: MultiAction, observation: MultiObservation | None,
              problem: MultiLabelProblem) -> MultiLabelBelief:
        """Bayes update for taking `action` and seeing `observation` (None: nothing seen)."""
        if self.finished(problem):
            raise DtSessionError("belief update after the multi-label search finished")
        if action.terminal:
            return self._after_claim(action, problem)
        observed = observation.per_label if observation is not None else None
        if observed is not None and len(observed) != problem.k:
            raise DtSessionError(f"{action}: {len(observed)} observations for {problem.k} labels")
        step = single_action(action)
        factors = list(self.factors)
        for i in self.open_labels:
            seen = NOTHING if observed is None else observed[i]
            if step.kind is ActionKind.PROCESS_VIEW_CONE and seen is NOTHING:
                raise DtSessionError(f"{action} needs a detection result for label "
                                     f"{problem.labels[i]!r}")
            try:
                factors[i] = factors[i].after(step, seen, problem.single(i).detector)
            except DtSessionError as error:
                raise DtSessionError(f"label {problem.labels[i]!r}: {error}") from error
        return MultiLabelBelief(action.cone, tuple(factors), self.claims,
                                action.kind is ActionKind.MOVE)

    def outcomes(self, action: MultiAction,
                 problem: MultiLabelProblem) -> list[tuple[float, MultiLabelBelief]]:
        """(probability, next belief) for each observation `action` can produce: a look has
        one per combination of the open labels' detections, with the product of the labels'
        own P(detection) (independent given where each label is)."""
        if action.kind is not ActionKind.PROCESS_VIEW_CONE:
            return [(1.0, self.after(action, None, problem))]
        open_labels = self.open_labels
        per_label = []
        for i in open_labels:
            hit = self.factors[i].p_detect(action.cone, problem.single(i).detector)
            per_label.append(((hit, DETECTED), (1.0 - hit, NOT_DETECTED)))
        branches = []
        for combination in product(*per_label):
            p = 1.0
            seen = [NOTHING] * problem.k
            for i, (p_i, obs) in zip(open_labels, combination, strict=True):
                p *= p_i
                seen[i] = obs
            if p > 0.0:
                branches.append((p, self.after(action, MultiObservation(tuple(seen)), problem)))
        return branches

    def _after_claim(self, action: MultiAction, problem: MultiLabelProblem) -> MultiLabelBelief:
        if action.label is None:
            raise DtSessionError(f"{action} names no label")
        try:
            i = problem.index(action.label)
        except DtInputError as error:
            raise DtSessionError(str(error)) from None
        if self.claims[i] != OPEN:
            raise DtSessionError(f"label {action.label!r} is already decided")
        if action.kind is ActionKind.CONFIRM:
            if not (self.factors[i].detected and action.cone == self.robot >= 0):
                raise DtSessionError(f"{action}: only a label just detected in the cone the "
                                     f"robot is at ({self.robot}) can be confirmed")
            claim = action.cone
        else:
            claim = NOWHERE
        factors = list(self.factors)
        factors[i] = factors[i].after(single_action(action), NOTHING, problem.single(i).detector)
        claims = self.claims[:i] + (claim,) + self.claims[i + 1:]
        return MultiLabelBelief(self.robot, tuple(factors), claims, self.after_move)
