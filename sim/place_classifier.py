"""A stand-in for visual place categorisation: a noisy category from a confusion matrix.

Given the true category of the room the robot stands in, it draws the category it "sees" from
that row of the matrix and reports the column P(seen | c) for every category c, which is exactly
the likelihood a Bayesian consumer multiplies into its room-category belief.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from sim.errors import SimError
from sim.sensor_data import PlaceObservation

DEFAULT_ACCURACY = 0.7  # a model parameter, not a measurement
# The categories a classifier knows when the caller gives none: a vocabulary of its own, never
# the categories of the building at hand (a one-category building would get a perfect one)
DEFAULT_CATEGORIES = ("corridor", "kitchen", "office", "meeting_room", "living_room", "bathroom")


@dataclass(frozen=True)
class PlaceClassifier:
    """confusion[true][seen] = P(seen | true); every row sums to 1 over the same categories."""

    confusion: Mapping[str, Mapping[str, float]]

    def __post_init__(self) -> None:
        categories = set(self.confusion)
        for true, row in self.confusion.items():
            if set(row) != categories:
                raise SimError(f"confusion[{true!r}]: must give a probability for each of "
                               f"{sorted(categories)}, got {sorted(row)}")
            if any(p < 0 for p in row.values()) or abs(sum(row.values()) - 1.0) > 1e-6:
                raise SimError(f"confusion[{true!r}]: probabilities must be >= 0 and sum to 1")

    @classmethod
    def with_accuracy(cls, categories: Iterable[str],
                      accuracy: float = DEFAULT_ACCURACY) -> PlaceClassifier:
        """Right with probability `accuracy`, otherwise any other category uniformly."""
        cats = sorted(set(categories))
        if len(cats) == 1:
            return cls({cats[0]: {cats[0]: 1.0}})
        wrong = (1.0 - accuracy) / (len(cats) - 1)
        return cls({t: {s: accuracy if s == t else wrong for s in cats} for t in cats})

    @property
    def categories(self) -> list[str]:
        return sorted(self.confusion)

    def observe(self, true_category: str, rng: np.random.Generator,
                time: float) -> PlaceObservation:
        """Draw what the classifier sees in a room of `true_category`."""
        row = self.confusion.get(true_category)
        if row is None:
            raise SimError(f"place classifier: no confusion row for category {true_category!r} "
                           f"(known: {', '.join(self.categories)})")
        cats = self.categories
        p = np.array([row[c] for c in cats], dtype=float)
        seen = cats[int(rng.choice(len(cats), p=p / p.sum()))]
        likelihood = {c: float(self.confusion[c][seen]) for c in cats}
        return PlaceObservation(observed=seen, likelihood=likelihood, time=time)
