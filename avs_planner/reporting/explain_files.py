"""Run folders and explanations on disk: reading a trace.jsonl, loading a folder's
explanation.json (or rebuilding it from the trace), and writing one."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from avs_planner.reporting.explain_ledger import build

FILE_NAME = "explanation.json"


class ExplainError(ValueError):
    """A run folder or trace that cannot be explained (the message names the file)."""


def read_trace(path: Path) -> list[dict[str, Any]]:
    """The events of a trace.jsonl; a bad line is an error naming the file and line."""
    events = []
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise ExplainError(f"{path}: cannot read the trace ({exc.strerror})") from None
    for n, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            event = json.loads(line)
        except json.JSONDecodeError as exc:
            raise ExplainError(f"{path}:{n}: not a JSON event ({exc.msg})") from None
        if not isinstance(event, dict):
            raise ExplainError(f"{path}:{n}: an event must be a JSON object")
        events.append(event)
    return events


def load(run_dir: Path, rebuild: bool = False) -> dict[str, Any]:
    """A run folder's explanation: its explanation.json, or rebuilt from its trace.jsonl
    (when there is none, or `rebuild`)."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise ExplainError(f"{run_dir}: no such run folder")
    saved = run_dir / FILE_NAME
    if saved.is_file() and not rebuild:
        try:
            data = json.loads(saved.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise ExplainError(f"{saved}: not a readable explanation ({exc})") from None
        if not isinstance(data, dict):
            raise ExplainError(f"{saved}: an explanation must be a JSON object")
        return data
    trace = run_dir / "trace.jsonl"
    if not trace.is_file():
        raise ExplainError(f"{run_dir}: neither {FILE_NAME} nor trace.jsonl is there (is it "
                           f"an episode's output folder?)")
    return build(read_trace(trace))


def write(path: Path, explanation: Mapping[str, Any]) -> None:
    """Save an explanation as indented JSON (a run folder's explanation.json)."""
    path.write_text(json.dumps(explanation, indent=2, default=str) + "\n", encoding="utf-8")
