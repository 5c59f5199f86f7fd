"""What lies behind a placeholder: the six structural hypotheses of §3 "Exploration" of the
active visual search paper (Göbelbecker et al.).

Each hypothesis adds 0, 1 or 2 hypothetical rooms hanging off the placeholder's room R, with the
category prior as their unary and phi_rc on the links. Because those rooms are leaves (or a chain)
off R, the marginals of the extended graph follow exactly from R's marginal in the current graph:
P(N1 = b) is proportional to prior(b) * sum_a P(R = a) phi(a, b). Hypotheses are weighted by a
likelihood from the open space behind the placeholder and whether it is behind a door.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.knowledge import Knowledge, PlaceholderModel

NO_NEW_ROOM = "none"
"""Key of `placeholder_category` results: the placeholder leads to no new room."""


class Hypothesis(enum.Enum):
    """Structure of the unexplored space behind a placeholder (in the order of the active visual
    search paper)."""

    NO_NEW_PLACES = 1
    PLACES_NO_ROOM = 2
    PLACES_THEN_ROOM = 3
    PLACES_THEN_TWO_ROOMS = 4
    ROOM_DIRECTLY = 5
    ROOM_THEN_ROOM = 6

    @property
    def new_rooms(self) -> int:
        """How many hypothetical rooms this hypothesis adds to the chain graph."""
        return {1: 0, 2: 0, 3: 1, 4: 2, 5: 1, 6: 2}[self.value]


@dataclass(frozen=True)
class PlaceholderEvidence:
    """What the place map knows about a placeholder: its room, open space, door belief."""

    room: str
    open_space_m2: float = 0.0
    p_door: float = 0.0

    def __post_init__(self) -> None:
        for name in ("open_space_m2", "p_door"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ConceptualError(f"{name} must be a number, got {value!r}")
        if not (math.isfinite(self.open_space_m2) and self.open_space_m2 >= 0.0):
            raise ConceptualError(f"open_space_m2 must be >= 0, got {self.open_space_m2!r}")
        if not 0.0 <= self.p_door <= 1.0:
            raise ConceptualError(f"p_door must be in [0, 1], got {self.p_door!r}")


@dataclass(frozen=True)
class PlaceholderPrediction:
    """P_category(placeholder) and how it was composed.

    `any_room[c]`: probability that the placeholder leads to at least one new room of category c
    (the active visual search paper's "any of the hypothesised rooms"); `first_room[c]`:
    probability that the first new room reached is of category c, so
    `sum(first_room) + no_new_room == 1`.
    """

    weights: MappingProxyType[Hypothesis, float]
    any_room: MappingProxyType[str, float]
    first_room: MappingProxyType[str, float]
    no_new_room: float


def hypothesis_weights(
    model: PlaceholderModel, evidence: PlaceholderEvidence
) -> dict[Hypothesis, float]:
    """Likelihood of each hypothesis, summing to 1.

    A door (probability p_door) leads directly to a room (5, or 6 if that room leads on).
    Without a door, new places exist with s = 1 - exp(-A / space_scale); given places, they form
    a room with r = 1 - exp(-A / room_area); any new room leads on with p_room_leads_on.
    """
    door, leads_on = evidence.p_door, model.p_room_leads_on
    space = -math.expm1(-evidence.open_space_m2 / model.space_scale_m2)
    room = -math.expm1(-evidence.open_space_m2 / model.room_area_m2)
    no_door = 1.0 - door
    return {
        Hypothesis.NO_NEW_PLACES: no_door * (1.0 - space),
        Hypothesis.PLACES_NO_ROOM: no_door * space * (1.0 - room),
        Hypothesis.PLACES_THEN_ROOM: no_door * space * room * (1.0 - leads_on),
        Hypothesis.PLACES_THEN_TWO_ROOMS: no_door * space * room * leads_on,
        Hypothesis.ROOM_DIRECTLY: door * (1.0 - leads_on),
        Hypothesis.ROOM_THEN_ROOM: door * leads_on,
    }


def predict(
    knowledge: Knowledge, room_marginal: np.ndarray, evidence: PlaceholderEvidence,
    weights: Mapping[Hypothesis, float] | None = None,
) -> PlaceholderPrediction:
    """Combine the hypotheses' category posteriors with their weights (`hypothesis_weights`
    unless given, e.g. calibrated to the building: `calibration.py`)."""
    if weights is None:
        weights = hypothesis_weights(knowledge.placeholder, evidence)
    one = _one_room(knowledge, room_marginal)
    first_of_two, any_of_two = _two_rooms(knowledge, room_marginal)
    any_room = np.zeros_like(one)
    first_room = np.zeros_like(one)
    for hypothesis, weight in weights.items():
        if hypothesis.new_rooms == 1:
            any_room += weight * one
            first_room += weight * one
        elif hypothesis.new_rooms == 2:
            any_room += weight * any_of_two
            first_room += weight * first_of_two
    no_room = weights[Hypothesis.NO_NEW_PLACES] + weights[Hypothesis.PLACES_NO_ROOM]
    names = knowledge.categories
    return PlaceholderPrediction(
        weights=MappingProxyType(weights),
        any_room=MappingProxyType(dict(zip(names, any_room.tolist(), strict=True))),
        first_room=MappingProxyType(dict(zip(names, first_room.tolist(), strict=True))),
        no_new_room=no_room,
    )


def _one_room(knowledge: Knowledge, room_marginal: np.ndarray) -> np.ndarray:
    """Marginal of a hypothetical room N1 linked only to R."""
    belief = knowledge.prior * (room_marginal @ knowledge.connectivity)
    return belief / belief.sum()


def _two_rooms(knowledge: Knowledge, room_marginal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the chain R - N1 - N2: marginal of N1, and P(N1 = c or N2 = c) for every c."""
    phi, prior = knowledge.connectivity, knowledge.prior
    joint = (prior * (room_marginal @ phi))[:, None] * phi * prior[None, :]
    joint /= joint.sum()
    first, second = joint.sum(axis=1), joint.sum(axis=0)
    return first, first + second - np.diag(joint)


def p_label_beyond(
    knowledge: Knowledge, room_marginal: np.ndarray, evidence: PlaceholderEvidence,
    room_lambda: np.ndarray, p_none: Callable[[np.ndarray], np.ndarray] | None = None,
    weights: Mapping[Hypothesis, float] | None = None,
) -> float:
    """P(at least one object in the new rooms behind the placeholder), where a new room of
    category c holds Poisson(`room_lambda[c]`) of them: each hypothesis's rooms with their
    category posterior (one room, or the chain N1 - N2 jointly), weighted as in `predict`.
    `p_none(m)`: P(no object where m are expected), exp(-m) unless the building's rate is
    uncertain (`ConceptualMap.rate_posterior`); two rooms share it, so their masses add.
    `weights`: as for `predict`."""
    none_of = p_none or (lambda m: np.exp(-m))
    if weights is None:
        weights = hypothesis_weights(knowledge.placeholder, evidence)
    lam = np.asarray(room_lambda, dtype=float)
    one = 1.0 - float(_one_room(knowledge, room_marginal) @ none_of(lam))
    phi, prior = knowledge.connectivity, knowledge.prior
    joint = (prior * (room_marginal @ phi))[:, None] * phi * prior[None, :]
    two = 1.0 - float(np.sum(joint / joint.sum() * none_of(lam[:, None] + lam[None, :])))
    by_rooms = {0: 0.0, 1: one, 2: two}
    return sum(w * by_rooms[h.new_rooms] for h, w in weights.items())
