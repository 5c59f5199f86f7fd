"""The episode's trace (one JSON event per line) and its summary (docs/architecture.md fields)."""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

Sink = Callable[[dict[str, Any]], None]


class Trace:
    """Stamps events with simulated and wall time, keeps them, writes and forwards them."""

    def __init__(self, clock: Callable[[], float], path: Path | None = None,
                 sink: Sink | None = None):
        self.clock = clock
        self.events: list[dict[str, Any]] = []
        self._sink = sink
        self._listeners: list[Sink] = []
        self._start = time.perf_counter()
        self._file: TextIO | None = path.open("w", encoding="utf-8") if path else None

    @property
    def wall(self) -> float:
        return time.perf_counter() - self._start

    def emit(self, type_: str, **fields: Any) -> dict[str, Any]:
        event = {"t": round(self.clock(), 3), "wall": round(self.wall, 3), "type": type_,
                 **fields}
        self.events.append(event)
        if self._file is not None:
            self._file.write(json.dumps(event, default=str) + "\n")
            self._file.flush()
        if self._sink is not None:
            self._sink(event)
        for listener in self._listeners:
            listener(event)
        return event

    def subscribe(self, listener: Sink) -> None:
        """Call `listener(event)` after each event is recorded (the map snapshots, the Rerun
        recorder; a listener may emit more events)."""
        self._listeners.append(listener)

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None


def write_summary(path: Path, summary: dict[str, Any]) -> None:
    path.write_text(json.dumps(summary, indent=2, default=str) + "\n", encoding="utf-8")
