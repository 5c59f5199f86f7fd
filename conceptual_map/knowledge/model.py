"""Commonsense knowledge as validated numpy tables, indexed by room category."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np

RELATIONS = ("in", "on")
"""Relations of an object to its support (a related space in the terms of the active visual
search paper by Göbelbecker et al.)."""


@dataclass(frozen=True)
class PropertyModel:
    """P(value | category) of one place property kind; `table[k, v]`, rows sum to 1."""

    kind: str
    values: tuple[str, ...]
    table: np.ndarray

    def index(self, value: str) -> int:
        """Column of `value`; ValueError if the kind has no such value."""
        return self.values.index(value)


@dataclass(frozen=True)
class PlaceholderModel:
    """Parameters of the likelihood of the six structural hypotheses behind a placeholder."""

    space_scale_m2: float
    room_area_m2: float
    p_room_leads_on: float


@dataclass(frozen=True)
class UnknownLabelModel:
    """The uninformed prior of a label the knowledge does not list (`Knowledge.with_label`).

    `rate`: expected number of the label in a room, the same for every room category (an
    unknown label says nothing about which rooms hold it). `room_share` of it lies directly in
    the room; the rest is shared evenly by the support instances a room of that category is
    expected to hold (each `supports` label's room lambda), `on` them.
    """

    rate: float = 0.5
    room_share: float = 0.5
    supports: tuple[str, ...] = ("table", "counter", "desk", "shelf")


@dataclass(frozen=True)
class MobilityModel:
    """How often objects of a label are moved, per day: a sighting `days` old still holds
    with P = exp(-rate x days) (the robot's building memory, `avs_planner/episode/memory.py`).
    Labels moved less often than `fixed_below` per day are the building's furniture: the
    memory keeps them as known objects; the others are sightings to be checked again."""

    default: float = 0.2
    fixed_below: float = 0.05
    rates: MappingProxyType[str, float] = field(
        default_factory=lambda: MappingProxyType({}))

    def rate(self, label: str) -> float:
        return self.rates.get(label, self.default)

    def still_there(self, label: str, days: float) -> float:
        """P(an object of `label` seen `days` ago has not been moved since)."""
        return float(np.exp(-self.rate(label) * max(days, 0.0)))

    def fixed(self, label: str) -> bool:
        return self.rate(label) < self.fixed_below


@dataclass(frozen=True)
class Knowledge:
    """Category priors, property likelihoods, phi_rc and Poisson lambdas for the chain graph."""

    source: str
    categories: tuple[str, ...]
    prior: np.ndarray
    properties: MappingProxyType[str, PropertyModel]
    connectivity: np.ndarray
    object_lambda: MappingProxyType[str, np.ndarray]
    default_object_lambda: float
    relation_lambda: MappingProxyType[tuple[str, str, str], np.ndarray]
    default_relation_lambda: float
    placeholder: PlaceholderModel
    unknown: UnknownLabelModel = field(default_factory=UnknownLabelModel)
    mobility: MobilityModel = field(default_factory=MobilityModel)
    rate_shape: float | None = None
    """Shape a of the Gamma(a, a) prior on a building's rate multiplier (mean 1): each
    label's counts in one building are Poisson(s x lambda) with s shared by its rooms, so
    looks that find nothing lower the expected count everywhere (`conceptual/existence.py`).
    None: the lambdas are taken as exact (independent Poisson counts per location)."""
    _category_index: dict[str, int] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self._category_index.update({c: i for i, c in enumerate(self.categories)})

    @property
    def labels(self) -> frozenset[str]:
        """Object labels with a room-level lambda."""
        return frozenset(self.object_lambda)

    def spelled(self, name: str) -> str:
        """`name` as the knowledge spells it, where it lists a label or category that
        differs only in case or in spaces for underscores ("CerealBox" -> "cerealbox",
        "Living Room" -> "living_room"); else `name` unchanged."""
        if name in self.object_lambda or name in self._category_index:
            return name
        key = _fold(name)
        for known in (*sorted(self.object_lambda), *self.categories):
            if _fold(known) == key:
                return known
        return name

    def category_index(self, category: str) -> int:
        """Index of `category`; KeyError naming it if unknown."""
        try:
            return self._category_index[category]
        except KeyError:
            raise KeyError(f"unknown room category {category!r}") from None

    def with_label(self, label: str) -> Knowledge:
        """This knowledge, plus `label` with the uninformed prior of `unknown` if it is not
        listed (unchanged if it is): `rate` expected per room in every category, `room_share`
        of it directly in the room, the rest spread evenly over the expected instances of the
        `unknown.supports` labels the knowledge lists (one lambda per support instance and
        category, the same for every support label)."""
        if label in self.object_lambda:
            return self
        model, n = self.unknown, len(self.categories)
        supports = [s for s in model.supports if s in self.object_lambda and s != label]
        direct = model.rate * (model.room_share if supports else 1.0)
        relations = dict(self.relation_lambda)
        if supports:
            expected = sum(self.object_lambda[s] for s in supports)  # supports per room
            per_support = np.divide(model.rate - direct, expected, out=np.zeros(n),
                                    where=expected > 0)
            for support in supports:
                relations[(label, "on", support)] = per_support.copy()
        return replace(self, object_lambda=MappingProxyType(
            {**self.object_lambda, label: np.full(n, direct)}),
            relation_lambda=MappingProxyType(relations), _category_index={})

    def room_lambda(self, label: str) -> np.ndarray:
        """Expected count of `label` directly in a room, per category (KeyError if unknown)."""
        try:
            return self.object_lambda[label]
        except KeyError:
            raise KeyError(f"unknown object label {label!r}") from None

    def relation_lambda_of(self, label: str, relation: str, support: str) -> np.ndarray:
        """Expected count of `label` `relation` one `support` instance, per category."""
        self.room_lambda(label)
        self.room_lambda(support)
        if relation not in RELATIONS:
            raise KeyError(f"unknown relation {relation!r} (expected one of {RELATIONS})")
        default = np.full(len(self.categories), self.default_relation_lambda)
        return self.relation_lambda.get((label, relation, support), default)

    def support_relations(self, label: str) -> dict[str, tuple[str, ...]]:
        """Support label -> the relations (`on`, `in`) the knowledge lists for `label` with it:
        where a search of a support looks (on its top, inside it)."""
        out: dict[str, tuple[str, ...]] = {}
        for lab, relation, support in self.relation_lambda:
            if lab == label:
                out[support] = (*out.get(support, ()), relation)
        return {s: tuple(r for r in RELATIONS if r in rels) for s, rels in out.items()}

    def support_lambda(self, label: str, support: str) -> np.ndarray:
        """Expected count of `label` at one `support` instance (on it and in it: the listed
        relations summed), per category; zeros if the knowledge lists neither."""
        total = np.zeros(len(self.categories))
        for relation in self.support_relations(label).get(support, ()):
            total = total + self.relation_lambda[(label, relation, support)]
        return total

    def total_room_lambda(self, label: str) -> np.ndarray:
        """Expected count of `label` anywhere in a room: direct plus on/in expected supports.

        The supports' own expected counts multiply their per-instance lambdas (the mean of the
        compound count), which is how the active visual search paper (Göbelbecker et al.) adds
        lambdas over sub-locations.
        """
        total = self.room_lambda(label).copy()
        for (lab, _rel, support), lam in self.relation_lambda.items():
            if lab == label:
                total += self.room_lambda(support) * lam
        return total


def _fold(name: str) -> str:
    """A name compared without case, surrounding spaces, or the difference between a
    space, a hyphen and an underscore."""
    return "_".join(name.strip().casefold().replace("-", " ").replace("_", " ").split())
