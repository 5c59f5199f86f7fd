"""When a planning call must end: one deadline for its grounding, greedy phase and restarts.

`SearchOptions.timeout_s` bounds a whole planning call (`planner.plan`, `improving_plans`),
so its clock starts before grounding, not when a search starts. Every phase reads the time
left from one `Deadline` and hands it to the search it starts (the engines check it after
each expansion), and no phase starts once it has passed. The clock is a parameter so tests
can drive it: a deadline decision never depends on how fast the machine is.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

Clock = Callable[[], float]  # seconds, monotonic (time.perf_counter)


@dataclass(frozen=True)
class Deadline:
    """`timeout_s` seconds after `start` on `clock` (no deadline when timeout_s is None)."""

    start: float
    timeout_s: float | None = None
    clock: Clock = field(default=time.perf_counter, compare=False)

    @classmethod
    def from_now(cls, timeout_s: float | None, clock: Clock = time.perf_counter) -> Deadline:
        return cls(clock(), timeout_s, clock)

    def elapsed(self) -> float:
        return self.clock() - self.start

    def left(self) -> float | None:
        """Seconds left (0 once passed), None without a timeout."""
        if self.timeout_s is None:
            return None
        return max(0.0, self.timeout_s - self.elapsed())

    def passed(self) -> bool:
        left = self.left()
        return left is not None and left <= 0.0

