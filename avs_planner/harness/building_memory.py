"""An episode's building memory, as the episode runner wires it (`episode/memory.py` is
what is kept and how a mind gets it back; `episode/recall.py` the check of sightings): the
spec's keys, loading and recalling before the run, the check before the strategy, and
saving after it, with the summary's `memory` part."""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avs_planner.episode import memory
from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.executor import Executor
from avs_planner.episode.mind import Mind
from avs_planner.episode.recall import check_remembered


def memory_keys(spec: Mapping[str, Any]) -> dict[str, Any]:
    """The spec's `memory` (a directory) and `since_s` (seconds since the building's last
    task), checked."""
    directory = spec.get("memory")
    if directory is not None and (not isinstance(directory, str | Path) or not str(directory)):
        raise EpisodeError(f"episode spec: 'memory' must be a directory, got {directory!r}")
    since = spec.get("since_s", 3600.0)
    if isinstance(since, bool) or not isinstance(since, int | float) \
            or not math.isfinite(since) or since < 0:
        raise EpisodeError(f"episode spec: 'since_s' must be a number >= 0 (simulated seconds "
                           f"since the building's previous task), got {since!r}")
    return {"memory": None if directory is None else str(directory), "since_s": float(since)}


@dataclass
class EpisodeMemory:
    """The building memory of one episode: its directory, the memory as loaded, the building
    time the task began, what was put into the mind, and what the check of its sightings
    found."""

    directory: str
    kept: memory.BuildingMemory | None
    start: float
    recalled: dict[str, Any] | None
    checked: int = 0
    confirmed: int = 0

    @classmethod
    def recall(cls, directory: str, since_s: float, mind: Mind) -> EpisodeMemory:
        """Load the memory in `directory` (none: a first task) into the fresh `mind`."""
        kept = memory.load(directory)
        start = (kept.clock if kept is not None else 0.0) + since_s
        recalled = memory.recall(mind, kept, start) if kept is not None else None
        return cls(directory, kept, start, recalled)

    def check(self, executor: Executor, labels: Collection[str],
              emit: Callable[..., Any], budget_left: Callable[[], bool]) -> None:
        """Look where the memory saw a wanted object (`check_remembered`)."""
        if not executor.mind.remembered:
            return

        def counted(kind: str, **fields: Any) -> None:
            if kind == "memory" and "checked" in fields:
                self.checked += 1
            emit(kind, **fields)

        self.confirmed = len(check_remembered(executor, labels, counted, budget_left))

    def keep(self, mind: Mind, same_spot: float) -> dict[str, Any]:
        """Write what the robot knows now to the memory (a sighting superseded by a later
        one within `same_spot` m, the executor's `same_object`, is not kept); the summary's
        `memory` part."""
        memory.save(memory.remember(mind, self.kept, self.start, same_spot), self.directory)
        recalled = self.recalled or {}
        return {"tasks_before": self.kept.tasks if self.kept is not None else 0,
                "building_clock_s": round(self.start, 1),
                "furniture": recalled.get("furniture", 0),
                "sightings": len(recalled.get("sightings", ())),
                "checked": self.checked, "confirmed": self.confirmed, "saved": True}
