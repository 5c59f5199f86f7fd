"""Exact belief over where the target is, plus the observed part (robot, last detection).

Because robot position and detections are observed, the belief is `n + 1` numbers (target in
cone i, or in none). Look counts per cone are kept too: they determine the belief exactly, so
`(robot, detected, after_move, hits, misses)` is a hashable key for exact search.
"""

from __future__ import annotations

from dataclasses import dataclass

import pomdp_py

from avs_planner.dt.domain import (
    NOWHERE,
    START,
    ActionKind,
    DTAction,
    DTObservation,
    DTState,
    ObservationKind,
)
from avs_planner.dt.errors import DtSessionError
from avs_planner.dt.inputs import DetectorModel
from avs_planner.dt.problem import DTProblem


@dataclass(frozen=True)
class TargetBelief:
    """P(target in cone i) for i < n, P(in none) last; robot index; last look detected?"""

    robot: int
    detected: bool
    probs: tuple[float, ...]
    hits: tuple[int, ...]
    misses: tuple[int, ...]
    after_move: bool = False
    done: bool = False

    @classmethod
    def initial(cls, problem: DTProblem) -> TargetBelief:
        zeros = (0,) * problem.n
        return cls(START, False, problem.prior, zeros, zeros)

    @property
    def n(self) -> int:
        return len(self.probs) - 1

    @property
    def p_none(self) -> float:
        return self.probs[-1]

    @property
    def p_present(self) -> float:
        """Probability that the target is in one of the cones."""
        return 1.0 - self.probs[-1]

    def p_target(self, cone: int) -> float:
        return self.probs[cone] if cone >= 0 else self.probs[-1]

    @property
    def key(self) -> tuple:
        """Exact identity of this belief (counts, not floats)."""
        return (self.robot, self.detected, self.after_move, self.done, self.hits, self.misses)

    def p_detect(self, cone: int, detector: DetectorModel) -> float:
        """P(a detection when processing `cone`) under this belief."""
        p = self.probs[cone]
        return p * detector.p_detect(True) + (1.0 - p) * detector.p_detect(False)

    def after(self, action: DTAction, observation: DTObservation,
              detector: DetectorModel) -> TargetBelief:
        """Bayes update for taking `action` and seeing `observation`."""
        if self.done:
            raise DtSessionError("belief update after CONFIRM/REJECT")
        if action.kind is ActionKind.MOVE:
            return TargetBelief(action.cone, False, self.probs, self.hits, self.misses, True)
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            return self._after_look(action.cone, observation, detector)
        return TargetBelief(self.robot, self.detected, self.probs, self.hits, self.misses,
                            False, True)

    def _after_look(self, cone: int, observation: DTObservation,
                    detector: DetectorModel) -> TargetBelief:
        if observation.kind is ObservationKind.NOTHING:
            raise DtSessionError(f"processing view cone {cone} needs a detection result")
        seen = observation.kind is ObservationKind.DETECTED
        in_cone = detector.p_detect(True) if seen else 1.0 - detector.p_detect(True)
        elsewhere = detector.p_detect(False) if seen else 1.0 - detector.p_detect(False)
        weights = [p * elsewhere for p in self.probs]
        weights[cone] = self.probs[cone] * in_cone
        total = sum(weights)
        if total <= 0.0:
            raise DtSessionError(
                f"observation {observation.kind.value} at cone {cone} is impossible under the "
                "detector model (check false_negative/false_positive)")
        hits, misses = list(self.hits), list(self.misses)
        (hits if seen else misses)[cone] += 1
        return TargetBelief(cone, seen, tuple(w / total for w in weights), tuple(hits),
                            tuple(misses))

    def to_histogram(self) -> pomdp_py.Histogram:
        """pomdp-py histogram over DTState (only targets with probability > 0)."""
        return pomdp_py.Histogram({
            DTState(self.robot, _target(i, self.n), self.detected, self.done): p
            for i, p in enumerate(self.probs) if p > 0.0
        })


def _target(index: int, n: int) -> int:
    return NOWHERE if index == n else index


def histogram_probs(histogram: pomdp_py.Histogram, n: int) -> tuple[float, ...]:
    """Marginal over the target (cones then none) of a pomdp-py histogram over DTState."""
    probs = [0.0] * (n + 1)
    for state in histogram:
        probs[state.target if state.target != NOWHERE else n] += histogram[state]
    total = sum(probs)
    return tuple(p / total for p in probs)
