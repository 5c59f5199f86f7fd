"""What executing one plan step produced: status, detail, observed atoms, reported object."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import Protocol

from avs_planner.cp.task import Atom
from avs_planner.episode.mind import KnownObject


class SeenLike(Protocol):
    label: str
    position: tuple[float, float, float]
    id: int


class StepStatus(Enum):
    DONE = "done"
    FAILED = "failed"
    FOUND = "found"  # REPORTPOSITION of a confirmed object


@dataclass
class StepOutcome:
    """What one executed step did; `observed` holds atoms about newly confirmed objects."""

    status: StepStatus
    detail: str = ""
    observed: dict[str, set[Atom]] = field(default_factory=dict)
    reported: KnownObject | None = None
