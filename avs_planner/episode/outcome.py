"""What a step produced (status, detail, observed atoms, reported object) and how a whole
search ended (`Outcome`, `SearchResult`: every strategy returns one)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import Any, Protocol

from avs_planner.cp.task import Atom
from avs_planner.episode.mind import KnownObject


class SeenLike(Protocol):
    label: str
    position: tuple[float, float, float]
    id: int


class Outcome(Enum):
    FOUND = "found"
    GAVE_UP = "gave_up"
    TIMEOUT = "timeout"


@dataclass
class SearchResult:
    """How a search ended; `plans`, `replans` and `cp_times` stay empty for strategies that
    do not plan with the CP; `details` go to the summary under `details`."""

    outcome: Outcome
    reason: str
    found: KnownObject | None = None
    plans: int = 0
    replans: int = 0
    cp_times: list[float] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)  # strategy-specific summary fields


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
