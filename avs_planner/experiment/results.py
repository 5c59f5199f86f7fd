"""The results table: one CSV row per run, the campaign's coordinates then the episode's numbers.

CSV because every tool reads it (pandas, R, a spreadsheet, `csv` in the standard library),
it needs no new dependency, and a 5,000-run campaign is a few hundred kilobytes; Parquet's
column compression and types buy nothing at that size. Lists from the summary (CP time per
plan, DT time per decision) become totals, counts and medians; the full lists stay in each
run's summary.json. Keys a summary may or may not carry (the DT's confirmations and
rejections, the map-quality scores in `map_score`) leave their cells empty when absent.

A task of several objects (`harness/tasks.py`) fills its row as one search does, for the whole
task (its outcome, sim time and verdict: `correct` when every report names a true instance of
its label, `false_report` when one does not), plus the task's own columns (`TASK_COLUMNS`):
which labels, each label's outcome, and counts of labels found, reports, true instances and
distinct ones reported; `targets_json` keeps each label's part (outcome, when it ended,
reports, instances) for the report. A single search leaves them empty.

A run's `status` is the campaign's view of it: `ok`; `wall_cut` when the episode ended
because its wall-clock budget ran out (a loaded machine, not the strategy: its numbers are not
comparable, and `--retry-failed` runs it again); `error`, `crashed` or `timeout` (killed past
its hard deadline) when it failed.
"""

from __future__ import annotations

import csv
import json
import math
import statistics
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from avs_planner.experiment.errors import CampaignError

RESULTS_FILE = "results.csv"
WALL_CUT = "wall_cut"
WALL_CUT_REASON = "wall time budget"  # how the episode loop and strategies word that stop
MAP_SCORE_KEYS = ("rooms_true", "rooms_matched", "merges", "splits", "category_accuracy",
                  "entered_area_m2", "entered_rooms", "entered_matched")
KEY_COLUMNS = ["run_id", "scenario", "world", "group", "target", "expected", "strategy",
               "robot", "seed"]
# a task of several objects: all, any or count, and its labels (space-separated); empty for
# one label (and absent from tables written before tasks: not required when read)
TASK_KEY_COLUMNS = ["task", "task_labels"]
# a task of a campaign sequence (`sequences.py`): the sequence's id, the task's index in it
# (the building's day) and the memory arm, on or off; empty otherwise (and absent from tables
# written before sequences: not required when read)
SEQUENCE_COLUMNS = ["sequence", "task_index", "memory"]
# a campaign with `priors` (`priors.py`): the arm, default (the knowledge file) or learned
# (the experience store's priors, read only); empty otherwise (and absent from older tables)
PRIORS_COLUMNS = ["priors"]
TASK_COLUMNS = ["targets_outcome", "targets_found", "reports", "reports_correct",
                "instances", "distinct", "targets_json"]
VALUE_COLUMNS = ["status", "error", "outcome", "reason", "correct", "success",
                 "correct_give_up", "false_report", "found_label", *TASK_COLUMNS,
                 "sim_time_s", "distance_m",
                 "plans", "replans", "cp_calls", "cp_time_s", "cp_s_per_plan", "dt_calls",
                 "dt_decisions", "dt_time_s", "dt_s_per_action", "dt_confirmed",
                 "dt_rejected", "views_processed",
                 *(f"map_{k}" for k in MAP_SCORE_KEYS),
                 "episode_s", "wall_s", "overhead_s", "backend", "commit"]
COLUMNS = KEY_COLUMNS + TASK_KEY_COLUMNS + SEQUENCE_COLUMNS + PRIORS_COLUMNS + VALUE_COLUMNS
_INTS = {"seed", "plans", "replans", "cp_calls", "dt_calls", "dt_decisions", "dt_confirmed",
         "dt_rejected", "views_processed", "targets_found", "reports", "reports_correct",
         "instances", "distinct", "task_index"}
_BOOLS = {"correct", "success", "correct_give_up", "false_report"}
_TEXT = {"run_id", "scenario", "world", "group", "target", "expected", "strategy", "robot",
         "status", "error", "outcome", "reason", "found_label", "backend", "commit", "task",
         "task_labels", "targets_outcome", "targets_json", "sequence", "memory", "priors"}


def is_wall_cut(outcome: Any, reason: Any) -> bool:
    """The episode stopped because its wall-clock budget was spent (not its simulated one)."""
    return outcome == "timeout" and WALL_CUT_REASON in str(reason or "")


def run_status(status: str, summary: Any) -> str:
    """The status to record for a run the worker reported as `status` with `summary`:
    `wall_cut` for an `ok` episode that the wall-clock budget cut short."""
    if status == "ok" and isinstance(summary, Mapping) and is_wall_cut(
            summary.get("outcome"), summary.get("reason")):
        return WALL_CUT
    return status


def row(record: Mapping[str, Any]) -> dict[str, Any]:
    """One table row from a run record (see runner.py); episode columns empty if it failed.

    A wall-cut run keeps its episode's numbers (how far it got) but no verdict: `correct`,
    `success`, `correct_give_up` and `false_report` stay empty."""
    out: dict[str, Any] = {k: record.get(k)
                           for k in KEY_COLUMNS + TASK_KEY_COLUMNS + SEQUENCE_COLUMNS
                           + PRIORS_COLUMNS}
    out.update({k: record.get(k) for k in ("status", "error", "episode_s", "wall_s",
                                           "overhead_s", "backend", "commit")})
    summary = record.get("summary")
    status = record.get("status")
    if status in ("ok", WALL_CUT) and isinstance(summary, Mapping):
        out.update(_summary_columns(summary, record.get("expected") or ""))
        if status == WALL_CUT:
            out.update(correct=None, success=None, correct_give_up=None, false_report=None)
    return out


def _summary_columns(s: Mapping[str, Any], expected: str) -> dict[str, Any]:
    outcome, correct = s.get("outcome"), bool(s.get("correct"))
    cp = [float(t) for t in s.get("cp_time_s") or []]
    dt = [float(t) for t in s.get("dt_decision_time_s") or []]
    found = outcome == "found"
    return {
        "outcome": outcome, "reason": s.get("reason"), "correct": correct,
        "success": found and correct if expected != "gave_up" else None,
        "correct_give_up": outcome == "gave_up" if expected == "gave_up" else None,
        "false_report": found and not correct,
        "found_label": (s.get("object") or {}).get("label"),
        "sim_time_s": s.get("sim_time_s"), "distance_m": s.get("distance_m"),
        "plans": s.get("plans"), "replans": s.get("replans"), "cp_calls": len(cp),
        "cp_time_s": round(sum(cp), 4), "cp_s_per_plan": _mean(cp),
        "dt_calls": s.get("dt_calls"), "dt_decisions": len(dt), "dt_time_s": round(sum(dt), 4),
        "dt_s_per_action": _mean(dt), "dt_confirmed": _count(s.get("dt_confirmed")),
        "dt_rejected": _count(s.get("dt_rejected")), "views_processed": s.get("views_processed"),
        **_map_score(s.get("map_score")),
        **_task_columns(s.get("targets")),
    }


def _task_columns(parts: Any) -> dict[str, Any]:
    """A task's own columns from its summary's `targets` (each label's part); a wrong report
    of any label is a false report of the task. Nothing for one label."""
    if not isinstance(parts, list) or not parts:
        return {}
    labels = [_part(p) for p in parts if isinstance(p, Mapping)]
    reports = sum(p["reports"] for p in labels)
    correct = sum(p["correct_reports"] for p in labels)
    return {
        "targets_outcome": " ".join(f"{p['label']}:{p['outcome']}" for p in labels),
        "targets_found": sum(p["outcome"] == "found" for p in labels),
        "reports": reports, "reports_correct": correct,
        "false_report": reports > correct,
        "instances": sum(p["instances"] or 0 for p in labels),
        "distinct": sum(p["distinct"] or 0 for p in labels),
        "targets_json": json.dumps(labels, separators=(",", ":")),
    }


def _part(part: Mapping[str, Any]) -> dict[str, Any]:
    """One label's part of a task (`harness/runner.py: _target_part`), as `targets_json`
    keeps it."""
    objects = [o for o in part.get("objects") or [] if isinstance(o, Mapping)]
    return {"label": part.get("label"), "outcome": part.get("outcome"),
            "sim_time_s": part.get("sim_time_s"), "reports": len(objects),
            "correct_reports": sum(bool(o.get("correct")) for o in objects),
            "instances": _count(part.get("instances")),
            "distinct": _count(part.get("distinct"))}


def _count(value: Any) -> int | None:
    """A count from the summary (a number, or a list of decisions), else None."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        return int(value)
    if isinstance(value, list):
        return len(value)
    return None


def _map_score(score: Any) -> dict[str, Any]:
    """The map-quality scores as `map_*` columns; absent or non-numeric ones stay empty."""
    score = score if isinstance(score, Mapping) else {}
    return {f"map_{k}": (v if isinstance(v, int | float) and not isinstance(v, bool)
                         and math.isfinite(v) else None)
            for k, v in ((k, score.get(k)) for k in MAP_SCORE_KEYS)}


def _mean(values: list[float]) -> float | None:
    return round(statistics.fmean(values), 4) if values else None


def write_results(out: Path, runs: Iterable[Any], records: Mapping[str, Mapping[str, Any]]
                  ) -> Path:
    """Write `out/results.csv`: the recorded runs, in the campaign's order."""
    path = out / RESULTS_FILE
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        for run in runs:
            record = records.get(run.run_id)
            if record is not None:
                writer.writerow({k: _cell(v) for k, v in row(record).items()})
    tmp.replace(path)
    return path


def _cell(value: Any) -> Any:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    return value


def read_results(path: Path) -> list[dict[str, Any]]:
    """The table back as typed rows (None for empty cells); CampaignError naming the file
    and what is wrong when it is not a results table (columns missing, a cell that is not
    of its column's type, not UTF-8 text)."""
    try:
        with path.open(newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            missing = [c for c in KEY_COLUMNS + ["status", "outcome"]
                       if c not in (reader.fieldnames or [])]
            if missing:
                raise CampaignError(f"{path}: not a results table of `avs experiment run`: "
                                    f"no column {', '.join(missing)}")
            rows = []
            for line, r in enumerate(reader, start=2):
                row = {}
                for k, v in r.items():
                    if k is None:
                        continue  # cells beyond the header's columns
                    try:
                        row[k] = _parse(k, v)
                    except ValueError:
                        raise CampaignError(f"{path}:{line}: column {k}: {v!r} is not a "
                                            f"value of that column") from None
                rows.append(row)
            return rows
    except UnicodeDecodeError as exc:
        raise CampaignError(f"{path}: not a UTF-8 text file ({exc.reason})") from None
    except csv.Error as exc:
        raise CampaignError(f"{path}: not a CSV table ({exc})") from None


def _parse(column: str, text: str | None) -> Any:
    if text is None or text == "":
        return None if column not in _TEXT else ""
    if column in _TEXT:
        return text
    if column in _BOOLS:
        return text == "true"
    if column in _INTS:
        return int(float(text))
    return float(text)
