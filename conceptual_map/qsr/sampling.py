"""From QSR descriptions to a Gaussian mixture: sample positions along each chain of relations
(eq. 1 inverted), fit one 2D Gaussian per description and landmark, weight by counts."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np

from conceptual_map.qsr.calculus import Landmark, place_objects, virtual_robot
from conceptual_map.qsr.mixture import GaussianMixture, fit_gaussian
from conceptual_map.qsr.model import DIRECTIONS, DISTANCES, QsrDescription, QsrKnowledge, QsrStep


class MixtureStatus(Enum):
    BUILT = "built"
    NO_DESCRIPTIONS = "no_descriptions"  # the knowledge says nothing about the target
    NO_LANDMARKS = "no_landmarks"  # descriptions exist, but none of their landmarks is known


@dataclass(frozen=True)
class MixtureResult:
    """The target's QSR mixture (when built) and the sampled positions behind each component."""

    status: MixtureStatus
    target: str
    mixture: GaussianMixture | None
    samples: tuple[np.ndarray, ...] = ()

    @property
    def built(self) -> bool:
        return self.status is MixtureStatus.BUILT


def sample_step(
    step: QsrStep, knowledge: QsrKnowledge, n: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Relative angles and distances (n each) for one step; no direction means any angle."""
    direction = step.relation(DIRECTIONS)
    if direction is None:
        angle = rng.uniform(0.0, 2.0 * math.pi, n)
    else:
        model = knowledge.relations[direction]
        angle = rng.normal(model.mean, model.std, n)
    dist = knowledge.relations[step.relation(DISTANCES) or knowledge.parameters.default_distance]
    return angle, np.abs(rng.normal(dist.mean, dist.std, n))


def sample_description(
    description: QsrDescription,
    landmark: Landmark,
    knowledge: QsrKnowledge,
    n: int,
    rng: np.random.Generator,
) -> np.ndarray:
    """n positions (n, 2) of the target: hallucinate each relatum of the chain from the landmark
    outward (e.g. keyboards in front of the monitor, then cups beside each keyboard)."""
    robot = virtual_robot(landmark, knowledge.parameters.origin_distance)
    points = np.tile(landmark.xy, (n, 1))
    for step in reversed(description.chain):
        angle, distance = sample_step(step, knowledge, n, rng)
        points = place_objects(robot, points, angle, distance)
    return points


def build_mixture(
    knowledge: QsrKnowledge,
    target: str,
    landmarks: Sequence[Landmark],
    rng: np.random.Generator | int | None = 0,
    samples: int | None = None,
) -> MixtureResult:
    """The mixture over the target's descriptions at every matching landmark instance.

    A description observed `count` times contributes `count` in total, split evenly between the
    instances of its landmark label (three monitors: a third each).
    """
    rng = np.random.default_rng(rng)
    n = samples or knowledge.parameters.samples
    descriptions = knowledge.descriptions_for(target)
    if not descriptions:
        return MixtureResult(MixtureStatus.NO_DESCRIPTIONS, target, None)
    parts, drawn = [], []
    for description in descriptions:
        instances = [lm for lm in landmarks if lm.label == description.landmark]
        for lm in instances:
            points = sample_description(description, lm, knowledge, n, rng)
            where = lm.name or f"{lm.label}@({lm.x:.2f}, {lm.y:.2f})"
            weight = description.count / len(instances)
            parts.append((weight, fit_gaussian(points), f"{description.text()} [{where}]"))
            drawn.append(points)
    if not parts:
        return MixtureResult(MixtureStatus.NO_LANDMARKS, target, None)
    return MixtureResult(MixtureStatus.BUILT, target, GaussianMixture.from_weighted(parts),
                         tuple(drawn))
