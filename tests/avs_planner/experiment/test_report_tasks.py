"""The report of a campaign with tasks of several objects, on hand-made summaries and rows."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from avs_planner.experiment.report import build_report
from avs_planner.experiment.report_tasks import task_and_singles, task_time_ratios
from avs_planner.experiment.results import COLUMNS, _cell, row


def _part(label: str, outcome: str, time: float | None, reports: tuple[bool, ...] = (),
          instances: int = 1, distinct: int | None = None) -> dict:
    """One label's part of a task's summary, as the episode writes it."""
    objects = [{"id": f"object{i}", "label": label, "truth": f"{label}{i}" if ok else "x",
                "correct": ok} for i, ok in enumerate(reports)]
    return {"label": label, "outcome": outcome, "reason": "", "objects": objects,
            "sim_time_s": time, "turns": 1, "instances": instances,
            "distinct": sum(reports) if distinct is None else distinct,
            "correct": all(reports)}


def _record(strategy: str, seed: int, target: str, outcome: str, time: float,
            expected: str = "found", world: str = "w", task: str = "",
            parts: list[dict] | None = None, status: str = "ok") -> dict:
    """A run record (runner.py) with the summary a single search or a task would write."""
    reports = [o for p in parts or [] for o in p["objects"]]
    correct = bool(reports) and all(o["correct"] for o in reports) if parts else \
        outcome == "found"
    summary = {"outcome": outcome, "reason": "", "target": target, "correct": correct,
               "object": {"label": target} if outcome == "found" and not parts else None,
               "sim_time_s": time, "distance_m": 10.0, "plans": 3, "replans": 0,
               "cp_time_s": [0.1], "dt_calls": 0, "dt_decision_time_s": []}
    if parts is not None:
        summary["targets"] = parts
    labels = " ".join(p["label"] for p in parts) if parts else ""
    slug = target.replace(" ", "-")
    return {"run_id": f"{world}-{slug}-{strategy}-s{seed}", "scenario": "", "world": world,
            "group": "g", "target": target, "expected": expected, "strategy": strategy,
            "robot": "", "seed": seed, "task": task, "task_labels": labels, "status": status,
            "error": None, "episode_s": 1.0, "wall_s": 1.1, "overhead_s": 0.1,
            "backend": "local", "commit": "abc1234", "summary": summary}


def _write(path: Path, records: list[dict]) -> None:
    with path.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        for record in records:
            writer.writerow({k: _cell(v) for k, v in row(record).items()})


def test_a_task_summary_fills_its_row_and_a_single_search_leaves_the_task_columns_empty():
    task = row(_record("S", 0, "cup and book", "found", 90.0, task="all", parts=[
        _part("cup", "found", 30.0, (True,), instances=3),
        _part("book", "found", 90.0, (False, True), instances=2)]))
    assert (task["task"], task["task_labels"], task["targets_outcome"],
            task["targets_found"], task["reports"], task["reports_correct"],
            task["instances"], task["distinct"]) == (
        "all", "cup book", "cup:found book:found", 2, 3, 2, 5, 2)
    assert (task["correct"], task["success"], task["false_report"]) == (False, False, True)
    assert json.loads(task["targets_json"])[1] == {
        "label": "book", "outcome": "found", "sim_time_s": 90.0, "reports": 2,
        "correct_reports": 1, "instances": 2, "distinct": 1}
    single = row(_record("S", 0, "cup", "found", 30.0))
    assert (single["task"], single["success"], single["false_report"]) == ("", True, False)
    assert all(k not in single for k in ("targets_outcome", "reports", "targets_json"))


def _campaign() -> list[dict]:
    """Strategy S in worlds w0-w3: an all task (cup and book) with both singles, an any task
    (cup or book), and a count task of chairs; see the test for the numbers."""
    records = []
    for k in range(4):
        world = f"w{k}"
        cup, book = 40.0 + 10 * k, 60.0 + 10 * k  # single searches: cup 40-70, book 60-90
        records += [_record("S", 0, "cup", "found", cup, world=world),
                    _record("S", 0, "book", "found" if k else "gave_up", book, world=world)]
        # all: 0.8 x (cup + book) where both singles found; the any task: 0.5 x cup
        records.append(_record("S", 0, "cup and book", "found", 0.8 * (cup + book),
                               world=world, task="all", parts=[
                                   _part("cup", "found", 0.3 * cup, (True,)),
                                   _part("book", "found", 0.8 * (cup + book), (True,))]))
        records.append(_record("S", 0, "cup or book", "found", 0.5 * cup, world=world,
                               task="any", parts=[_part("cup", "found", 0.5 * cup, (True,)),
                                                  _part("book", "not_needed", None)]))
    # count tasks: all 3 of 3 then stopped; 2 of 4 then stopped; 1 of 2 and out of time;
    # a wrong report beside 2 of 3
    for k, (outcome, instances, reports) in enumerate([
            ("found", 3, (True, True, True)), ("found", 4, (True, True)),
            ("timeout", 2, (True,)), ("found", 3, (True, True, False))]):
        records.append(_record("S", 0, "every chair", outcome, 300.0 + k, world=f"w{k}",
                               task="count", parts=[_part("chair", outcome, 300.0 + k,
                                                          reports, instances)]))
    return records


def test_task_vs_single_search_ratios_on_hand_made_numbers(tmp_path):
    _write(tmp_path / "results.csv", _campaign())
    from avs_planner.experiment.results import read_results

    rows = read_results(tmp_path / "results.csv")
    tuples = task_and_singles(rows)
    assert sorted((t.task["task"], t.task["world"]) for t in tuples) == sorted(
        (kind, f"w{k}") for kind in ("all", "any") for k in range(4))
    assert all([s["target"] for s in t.singles] == ["cup", "book"] for t in tuples)
    # w0's book single gave up: that tuple is not among those where all found
    ratios = task_time_ratios([t for t in tuples if t.task["task"] == "all"])
    assert ratios["sum"] == pytest.approx([0.8] * 3)
    any_ratios = task_time_ratios([t for t in tuples if t.task["task"] == "any"])
    assert any_ratios["min"] == pytest.approx([0.5] * 3)
    assert any_ratios["max"] == pytest.approx([0.5 * (40 + 10 * k) / (60 + 10 * k)
                                               for k in (1, 2, 3)])
    # a wall-cut single, or a missing one, leaves the tuple out
    rows[0]["status"] = "wall_cut"
    assert len(task_and_singles(rows)) == 6
    assert len(task_and_singles([r for r in rows if r["target"] != "book"])) == 0


def test_the_report_of_a_campaign_with_tasks(tmp_path):
    _write(tmp_path / "results.csv", _campaign())
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    # the single-label tables count the single searches only (8 runs, 7 found)
    assert "| S | 8 | 0.88 [0.53, 0.98] (7/8) |" in report
    # per kind: as expected, labels found, false reports, timeouts, wall cuts, failed, time
    assert ("| all | S | all | 4 | 4/4 = 100% [51, 100] | 8/8 | 0 of 8 | 0 | 0 | 0 | "
            "104 / 123 |") in report
    assert ("| all | S | any | 4 | 4/4 = 100% [51, 100] | 4/4 (4 not needed) | 0 of 4 | 0 "
            "| 0 | 0 | 28 / 34 |") in report
    assert ("| all | S | count | 4 | 2/4 = 50% [15, 85] | 3/4 | 1 of 9 | 1 | 0 | 0 | "
            "302 / 303 |") in report
    # each label: the book of the any tasks was never needed
    assert "| S | any | book | 4 | -- | 0 | 0 | 4 | 0 | -- |" in report
    assert "| S | count | chair | 4 | 3/4 = 75% [30, 95] | 0 | 1 | 0 | 1 | 301 |" in report
    # counting: 3 + 2 + 1 + 2 of 3 + 4 + 2 + 3 instances; per run 1, 0.5, 0.5, 0.67;
    # stops: 3 of 3 left none, 2 of 4 and 2 of 3 left some; one timeout; one wrong report
    assert ("| all | S | 4 | 8/12 = 67% | 0.58 | 1/3 = 33% [6, 79] | 2 | 1 | 1 of 9 |"
            in report)
    # beside the singles: 0.8 of the sum, 0.5 of the shortest (n 3: w0's book gave up)
    assert ("| all | S | all | 4 | 3 | 0.80 [0.80, 0.80] (n 3) | · | · |") in report
    assert "| all | S | any | 4 | 3 | · | 0.50 [0.50, 0.50] (n 3) | 0.3" in report
    for title in ("Tasks of several objects", "Tasks: each label", "Counting every instance",
                  "Tasks beside the single searches of their labels"):
        section = report.split(f"## {title}\n")[1]
        assert section.startswith(f"\n_Campaign {tmp_path.name}, run on an unrecorded date, "
                                  f"commit abc1234._")


def test_the_single_label_tables_do_not_change_when_tasks_join_them(tmp_path):
    records = _campaign()
    singles = [r for r in records if not r["task"]]
    for name, mine in (("a", singles), ("b", records)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "campaign.json").write_text('{"name": "c"}')
        _write(tmp_path / name / "results.csv", mine)
    alone = build_report(tmp_path / "a", tmp_path / "a" / "report.md").read_text()
    mixed = build_report(tmp_path / "b", tmp_path / "b" / "report.md").read_text()

    def tables(text: str) -> str:
        return text.split("## Per strategy")[1].split("\n## Tasks of several")[0].split(
            "\n## Plots")[0]

    assert "## Tasks" not in alone
    assert tables(mixed) == tables(alone)


def test_a_campaign_of_tasks_only_has_no_single_label_tables(tmp_path):
    _write(tmp_path / "results.csv", [r for r in _campaign() if r["task"]])
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    assert "## Per strategy" not in report and "## Plots" not in report
    assert "## Tasks of several objects" in report
    assert "## Tasks beside the single searches" not in report  # no singles to pair with
