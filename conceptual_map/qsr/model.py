"""QSR knowledge as validated values: relation models, landmark fronts, weighted descriptions."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

from conceptual_map.qsr.calculus import Landmark

DIRECTIONS = ("behind", "left", "front", "right")
"""Directional relations, in the order of their mean relative angles 0, pi/2, pi, 3pi/2."""
DISTANCES = ("close", "distant")
RELATION_NAMES = DIRECTIONS + DISTANCES


@dataclass(frozen=True)
class RelationModel:
    """A Gaussian over the relative angle (rad, directions) or distance (m, distances)."""

    name: str
    mean: float
    std: float

    @property
    def is_direction(self) -> bool:
        return self.name in DIRECTIONS


@dataclass(frozen=True)
class QsrStep:
    """The relations (at most one direction, one distance) of a thing to a relatum label `of`."""

    relations: tuple[str, ...]
    of: str

    def relation(self, kind: tuple[str, ...]) -> str | None:
        """This step's relation among `kind` (DIRECTIONS or DISTANCES), if it has one."""
        return next((r for r in self.relations if r in kind), None)


@dataclass(frozen=True)
class QsrDescription:
    """Where `target` is: a chain of steps from it outward, ending at a landmark label.

    `chain[0]` relates the target to `chain[0].of`, `chain[1]` relates that to the next, and
    so on; `count` is how often this description was observed (the mixture weight).
    """

    target: str
    chain: tuple[QsrStep, ...]
    count: float

    @property
    def landmark(self) -> str:
        return self.chain[-1].of

    @property
    def key(self) -> tuple[str, tuple[QsrStep, ...]]:
        """Identity of the description without its count (for learning updates)."""
        return (self.target, self.chain)

    def text(self) -> str:
        """The QSR paper's notation, e.g. `right(cup, keyboard) & front(keyboard, monitor)`."""
        parts, referent = [], self.target
        for step in self.chain:
            parts += [f"{rel}({referent}, {step.of})" for rel in step.relations]
            referent = step.of
        return " & ".join(parts)


@dataclass(frozen=True)
class QsrParameters:
    """Global model parameters (see the README for what each one means)."""

    origin_distance: float = 1.0
    close_ratio: float = 0.5
    default_distance: str = "close"
    samples: int = 300
    learn_radius: float = 0.8


@dataclass(frozen=True)
class QsrKnowledge:
    """Relation Gaussians, landmark fronts (rad in the landmark's frame) and descriptions."""

    source: str
    parameters: QsrParameters
    relations: Mapping[str, RelationModel]
    fronts: Mapping[str, float]
    descriptions: tuple[QsrDescription, ...]

    def descriptions_for(self, target: str) -> tuple[QsrDescription, ...]:
        return tuple(d for d in self.descriptions if d.target == target)

    def with_descriptions(self, descriptions: tuple[QsrDescription, ...]) -> QsrKnowledge:
        """The same models with other descriptions (e.g. ones a task carries, or learnt ones)."""
        return dataclasses.replace(self, descriptions=tuple(descriptions))

    def landmark(self, label: str, x: float, y: float, yaw: float, name: str = "") -> Landmark:
        """A landmark at pose (x, y, yaw): its front is `yaw` turned by the label's front angle."""
        if label not in self.fronts:
            raise KeyError(f"{label!r} is not a landmark label (known: {sorted(self.fronts)})")
        return Landmark(label, x, y, yaw + self.fronts[label], name)

    def direction_means(self) -> dict[str, float]:
        return {name: self.relations[name].mean for name in DIRECTIONS}

    @property
    def close_threshold(self) -> float:
        """Distance (m) below which a thing is close to a landmark, with the robot where eq. 1
        imagines it (`origin_distance` in front)."""
        return self.parameters.close_ratio * self.parameters.origin_distance
