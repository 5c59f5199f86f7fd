"""What placeholders in this building turned out to lead to: the placeholder model, calibrated.

The six hypotheses of `placeholders.py` give each placeholder a probability q that a new room
lies behind it, from the open space behind its frontier and whether a door hypothesis is near.
Those two readings say little in some buildings: a frontier in an open-plan office has as much
unknown space behind it as a doorway, and on the development campaign (generated offices,
apartments and labs, building seeds 300-305; docs/results.md) the model gave 3207 frontiers
without a door a mean q of 0.63 where 0.30 led to a new room, and 653 at a door 0.97 where
0.41 did. The robot then drove to placeholder after placeholder, each time assuming an office
beyond it.

The robot sees how its own placeholders ended (`avs_planner/episode/placeholder_outcomes.py`
decides that from its own map: the space behind the frontier became a room that did not exist
before, or a room it knew, or a wall). Here those outcomes correct the model in this building:
a logit offset b per kind of placeholder (near a door hypothesis or not), so that a
placeholder's probability of a new room is sigmoid(logit(q) + b). b is the maximum a
posteriori estimate under a normal prior N(0, `PRIOR_SD`^2) over the recorded (q, outcome)
pairs of its kind: with nothing recorded b = 0 and the model is as written; every outcome
moves it, a handful of them enough to matter. The hypotheses that add a room keep their
shares of the new-room probability, those that add none theirs of the rest
(`calibrated_weights`).

Outcomes are always recorded (`summary`); the offset changes predictions only when `apply`
is set (the switching strategy's `calibrate_placeholders` option, off by default). On the
development campaign (generated building seeds 300-305) applying it left the paired time to
find unchanged (median switching / exhaustive 0.98 with and without), and it gave up on a
target behind a door seen obliquely at the end of a corridor whose other frontiers had led
nowhere: grouping placeholders only by door or not lumps that doorway with the corridor's
ends. Until the model tells such frontiers apart (e.g. by the frontier's width), the
correction is measured, not used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from conceptual_map.conceptual.placeholders import (
    Hypothesis,
    PlaceholderEvidence,
    hypothesis_weights,
)
from conceptual_map.knowledge import PlaceholderModel

PRIOR_SD = 1.0  # logit units: a weakly informative prior on the offset, chosen a priori
Q_EPS = 1e-4  # q is kept in [Q_EPS, 1 - Q_EPS] before its logit
OFFSET_BOUND = 30.0  # |b| never exceeds this (the prior alone keeps it near a few units)


def new_room_probability(weights: Mapping[Hypothesis, float]) -> float:
    """The hypotheses' probability that at least one new room lies behind the placeholder."""
    return float(sum(w for h, w in weights.items() if h.new_rooms > 0))


def calibrated_weights(weights: Mapping[Hypothesis, float],
                       offset: float) -> dict[Hypothesis, float]:
    """`weights` with the new-room probability q moved to sigmoid(logit(q) + `offset`): the
    room-bearing hypotheses scaled by q'/q, the others by (1 - q')/(1 - q). An offset of 0,
    or a q of 0 or 1 (nothing to move), leaves them as they are."""
    q = new_room_probability(weights)
    if offset == 0.0 or q <= 0.0 or q >= 1.0:
        return dict(weights)
    q_new = _sigmoid(_logit(q) + offset)
    return {h: w * (q_new / q if h.new_rooms > 0 else (1.0 - q_new) / (1.0 - q))
            for h, w in weights.items()}


def kind_of(evidence: PlaceholderEvidence) -> str:
    """The placeholders that share an offset: near a door hypothesis, or not."""
    return "door" if evidence.p_door > 0.0 else "open"


@dataclass
class PlaceholderCalibration:
    """The outcomes of this building's placeholders and the offsets they give (module doc)."""

    model: PlaceholderModel
    prior_sd: float = PRIOR_SD
    apply: bool = False  # predictions use the offsets (else they are only measured)
    # kind -> (logit of the model's q, 1 if a new room lay behind it else 0), in order seen
    outcomes: dict[str, list[tuple[float, int]]] = field(default_factory=dict)
    _offsets: dict[str, float] = field(default_factory=dict, repr=False)

    def record(self, evidence: PlaceholderEvidence, led_to_new_room: bool) -> None:
        """A placeholder with `evidence` (as it was when it vanished) led to a new room, or
        not. The model's own q (never a calibrated one) is what the offset corrects."""
        q = new_room_probability(hypothesis_weights(self.model, evidence))
        kind = kind_of(evidence)
        self.outcomes.setdefault(kind, []).append(
            (_logit(min(max(q, Q_EPS), 1.0 - Q_EPS)), int(bool(led_to_new_room))))
        self._offsets.pop(kind, None)

    def offset(self, evidence: PlaceholderEvidence) -> float:
        """The logit offset for placeholders of `evidence`'s kind (0 with nothing recorded)."""
        return self._offset(kind_of(evidence))

    def _offset(self, kind: str) -> float:
        if kind not in self._offsets:
            self._offsets[kind] = map_offset(self.outcomes.get(kind, []), self.prior_sd)
        return self._offsets[kind]

    def weights(self, evidence: PlaceholderEvidence) -> dict[Hypothesis, float]:
        """The hypotheses' weights for `evidence`: calibrated to this building when `apply`
        is set, else the model's own."""
        weights = hypothesis_weights(self.model, evidence)
        return calibrated_weights(weights, self.offset(evidence)) if self.apply else weights

    def summary(self) -> dict[str, dict[str, float]]:
        """Per kind: outcomes recorded, how many led to a new room, the model's mean
        P(new room) for them, and the offset they give (for traces and summaries)."""
        return {kind: {"resolved": len(rows), "new_room": sum(y for _, y in rows),
                       "predicted": round(sum(_sigmoid(z) for z, _ in rows) / len(rows), 4),
                       "offset": round(self._offset(kind), 3)}
                for kind, rows in sorted(self.outcomes.items())}


def map_offset(rows: list[tuple[float, int]], prior_sd: float = PRIOR_SD) -> float:
    """The b maximising sum(y log s(z + b) + (1 - y) log(1 - s(z + b))) - b^2 / (2 sd^2) over
    `rows` of (z, y): the root of its derivative, which falls strictly in b (Newton's steps,
    kept inside the bracket that holds the root, else halving it; plain Newton overshoots
    when many outcomes sit far from the model)."""
    if not rows:
        return 0.0
    precision = 1.0 / (prior_sd * prior_sd)
    lo, hi = -OFFSET_BOUND, OFFSET_BOUND
    b = 0.0
    for _ in range(200):
        grad, curvature = -b * precision, precision
        for z, y in rows:
            s = _sigmoid(z + b)
            grad += y - s
            curvature += s * (1.0 - s)
        if grad > 0.0:
            lo = b
        else:
            hi = b
        step = grad / curvature
        nxt = b + step
        if not lo < nxt < hi:
            nxt = 0.5 * (lo + hi)
        if abs(nxt - b) < 1e-10:
            return nxt
        b = nxt
    return b


def _logit(p: float) -> float:
    return math.log(p / (1.0 - p))


def _sigmoid(x: float) -> float:
    if x >= 0:
        return 1.0 / (1.0 + math.exp(-x))
    e = math.exp(x)
    return e / (1.0 + e)
