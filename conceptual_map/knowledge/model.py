"""Commonsense knowledge as validated numpy tables, indexed by room category."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

RELATIONS = ("in", "on")
"""Relations of an object to its support (a related space in seed 003's terms)."""


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
    _category_index: dict[str, int] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self._category_index.update({c: i for i, c in enumerate(self.categories)})

    @property
    def labels(self) -> frozenset[str]:
        """Object labels with a room-level lambda."""
        return frozenset(self.object_lambda)

    def category_index(self, category: str) -> int:
        """Index of `category`; KeyError naming it if unknown."""
        try:
            return self._category_index[category]
        except KeyError:
            raise KeyError(f"unknown room category {category!r}") from None

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

    def total_room_lambda(self, label: str) -> np.ndarray:
        """Expected count of `label` anywhere in a room: direct plus on/in expected supports.

        The supports' own expected counts multiply their per-instance lambdas (the mean of the
        compound count), which is how seed 003 adds lambdas over sub-locations.
        """
        total = self.room_lambda(label).copy()
        for (lab, _rel, support), lam in self.relation_lambda.items():
            if lab == label:
                total += self.room_lambda(support) * lam
        return total
