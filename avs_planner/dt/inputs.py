"""What a DT session is given besides its belief: the view cones and the detector's noise.

Plain values without pomdp-py, so the mind's side (view cones, the executor's settings) can
hold them without importing the POMDP solver (~0.7 s) before a DT session runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from avs_planner.dt.errors import DtInputError

Pose2D = tuple[float, float, float]


@dataclass(frozen=True)
class ViewCone:
    """A sensing action: robot pose (x, y, yaw), optional PR2 head/torso, P(target inside)."""

    id: str
    pose: Pose2D
    probability: float
    head: tuple[float, float] | None = None  # pan, tilt (rad)
    torso: float | None = None  # lift (m)

    def check(self, where: str) -> None:
        """Raise DtInputError naming `where` if the cone is malformed."""
        if not self.id:
            raise DtInputError(f"{where}: view cone id is empty")
        if len(self.pose) != 3 or not all(math.isfinite(v) for v in self.pose):
            raise DtInputError(f"{where} ({self.id}): pose must be 3 finite numbers (x, y, yaw)")
        if not (0.0 <= self.probability <= 1.0) or math.isnan(self.probability):
            raise DtInputError(
                f"{where} ({self.id}): probability {self.probability} is not in [0, 1]"
            )


@dataclass(frozen=True)
class DetectorModel:
    """Object detector noise: P(miss | object in cone), P(hit | object not in cone)."""

    false_negative: float = 0.2
    false_positive: float = 0.05

    def __post_init__(self) -> None:
        for name in ("false_negative", "false_positive"):
            value = getattr(self, name)
            if not (0.0 <= value < 1.0):
                raise DtInputError(f"detector: {name}={value} must be in [0, 1)")
        if self.false_negative + self.false_positive >= 1.0:
            raise DtInputError(
                "detector: false_negative + false_positive must be < 1 "
                "(otherwise a detection carries no evidence)"
            )

    def p_detect(self, target_in_cone: bool) -> float:
        """P(detection | whether the target is in the processed cone)."""
        return 1.0 - self.false_negative if target_in_cone else self.false_positive
