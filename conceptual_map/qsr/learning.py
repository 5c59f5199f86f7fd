"""Learning QSR counts from what was seen (the QSR paper's future work, kept simple).

When the target is found, its relation to each nearby visible landmark is classified with eq. 1
(nearest directional mean; close below the relative-radius threshold) and the matching one-step
description gains one observation; an unseen combination becomes a new description.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from conceptual_map.qsr.calculus import (
    Landmark,
    nearest_direction,
    relative_angle,
    relative_radius,
    virtual_robot,
)
from conceptual_map.qsr.model import QsrDescription, QsrKnowledge, QsrStep


@dataclass(frozen=True)
class LearningUpdate:
    """The knowledge after one observation, and the descriptions it credited."""

    knowledge: QsrKnowledge
    credited: tuple[QsrDescription, ...]


def classify(position: Sequence[float], landmark: Landmark, knowledge: QsrKnowledge) -> QsrStep:
    """The QSRs (one direction, one distance) of a point to a landmark, by eq. 1."""
    robot = virtual_robot(landmark, knowledge.parameters.origin_distance)
    point = np.asarray(position[:2], dtype=float)
    phi = float(relative_angle(robot, landmark.xy, point))
    direction = nearest_direction(phi, knowledge.direction_means())
    ratio = float(relative_radius(robot, landmark.xy, point))
    distance = "close" if ratio < knowledge.parameters.close_ratio else "distant"
    return QsrStep((direction, distance), landmark.label)


def nearby_landmarks(
    position: Sequence[float], landmarks: Sequence[Landmark], radius: float
) -> list[Landmark]:
    """The nearest instance of each landmark label within `radius` of the position."""
    point = np.asarray(position[:2], dtype=float)
    best: dict[str, tuple[float, Landmark]] = {}
    for lm in landmarks:
        d = float(np.linalg.norm(lm.xy - point))
        if d <= radius and (lm.label not in best or d < best[lm.label][0]):
            best[lm.label] = (d, lm)
    return [lm for _, lm in best.values()]


def learn_from_observation(
    knowledge: QsrKnowledge,
    target: str,
    position: Sequence[float],
    visible: Sequence[Landmark],
) -> LearningUpdate:
    """Add one observation of `target` at `position` relative to the visible landmarks near it."""
    near = nearby_landmarks(position, visible, knowledge.parameters.learn_radius)
    descriptions = list(knowledge.descriptions)
    index = {d.key: i for i, d in enumerate(descriptions)}
    credited = []
    for lm in near:
        step = classify(position, lm, knowledge)
        key = (target, (step,))
        if key in index:
            old = descriptions[index[key]]
            descriptions[index[key]] = QsrDescription(target, old.chain, old.count + 1.0)
        else:
            index[key] = len(descriptions)
            descriptions.append(QsrDescription(target, (step,), 1.0))
        credited.append(descriptions[index[key]])
    return LearningUpdate(knowledge.with_descriptions(tuple(descriptions)), tuple(credited))
