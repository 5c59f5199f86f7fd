"""Reading a recording back: what `avs view --check` prints and the tests check."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from avs_planner.viewer.errors import ViewerError, require_rerun
from avs_planner.viewer.recorder import TIMELINE


def contents(path: Path) -> dict[str, Any]:
    """Entity path -> rows logged on the sim_time timeline, and the timeline's range (s)."""
    require_rerun("reading a recording")
    from rerun.chunk import RrdReader

    try:
        reader = RrdReader(str(path))
        entities: dict[str, int] = {}
        lo, hi = float("inf"), float("-inf")
        for chunk in reader.stream():
            entities[chunk.entity_path] = entities.get(chunk.entity_path, 0) + chunk.num_rows
            if TIMELINE in chunk.timeline_names:
                batch = chunk.to_record_batch()
                column = batch.column(TIMELINE).to_pylist()
                values = [v.total_seconds() if hasattr(v, "total_seconds") else v / 1e9
                          for v in column if v is not None]
                if values:
                    lo, hi = min(lo, min(values)), max(hi, max(values))
    except ViewerError:
        raise
    except Exception as exc:  # noqa: BLE001 - rerun's reader raises its own error types
        raise ViewerError(f"{path}: not a readable Rerun recording ({exc})") from None
    return {"entities": entities, "sim_time": (lo, hi) if lo <= hi else None}


def describe(path: Path) -> str:
    data = contents(path)
    lines = [f"{path}: {len(data['entities'])} entities"]
    span = data["sim_time"]
    if span is not None:
        lines.append(f"  {TIMELINE}: {span[0]:.1f} s .. {span[1]:.1f} s")
    for entity, rows in sorted(data["entities"].items()):
        lines.append(f"  {entity}: {rows} rows")
    return "\n".join(lines)
