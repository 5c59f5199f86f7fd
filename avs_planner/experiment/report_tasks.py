"""The report's task tables: campaigns whose targets include tasks of several objects.

A task (`harness/tasks.py`) asks for one object of each of several labels (`all`), one of any
of them (`any`) or every instance of one label (`count`); results.csv holds one row per task
episode with the whole task's outcome and time, and each label's part in `targets_json`
(`results.py`). The report gives, per strategy and kind of task: how often the task ended as
expected, the labels found and the reports that named a wrong object, and the whole task's
simulated time; per label, how often its part was found; for count tasks, the share of the
true instances found and how the task stopped (no instance left unfound, or some left); and,
where the campaign also ran the single-label searches of a task's labels on the same world,
robot, seed and strategy, the paired ratios of the task's time to theirs.

`task_and_singles` and `task_time_ratios` are also for scripts (a benchmark reading
results.csv): the tuples of a task run and its labels' single runs, and the ratios per tuple.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from avs_planner.experiment.report_cells import num, percent_cell, ratio_cell, spread_cell
from avs_planner.experiment.report_header import stamped
from avs_planner.experiment.report_rows import (
    Row,
    comparable,
    is_failed,
    is_timeout,
    slices,
)
from avs_planner.experiment.results import WALL_CUT
from avs_planner.experiment.stats import median, wilson

KINDS = ("all", "any", "count")
NOT_NEEDED = "not_needed"  # a label an `any` task did not need (`harness/tasks.py`)
RATIOS = {"all": ("sum",), "any": ("min", "max")}  # the paired ratios each kind is read by


def is_task(row: Row) -> bool:
    """A task of several objects (the `task` column: all, any or count)."""
    return bool(row.get("task"))


def parts(row: Row) -> list[dict[str, Any]]:
    """Each label's part of a task run (`targets_json`); none when it has none."""
    text = row.get("targets_json")
    if not text:
        return []
    try:
        value = json.loads(text)
    except ValueError:
        return []
    return [p for p in value if isinstance(p, dict)] if isinstance(value, list) else []


def task_tables(rows: list[Row], stamp: str) -> list[str]:
    """The task sections of the report; nothing when the campaign has no tasks."""
    tasks = [r for r in rows if is_task(r)]
    if not tasks:
        return []
    strategies = list(dict.fromkeys(r["strategy"] for r in tasks))
    kinds = [k for k in KINDS if any(r["task"] == k for r in tasks)]
    return (_summary_table(tasks, strategies, kinds, stamp)
            + _label_table(tasks, strategies, kinds, stamp)
            + _count_table(tasks, strategies, stamp)
            + singles_table(rows, strategies, stamp))


def _summary_table(tasks: list[Row], strategies: list[str], kinds: list[str], stamp: str
                   ) -> list[str]:
    lines = stamped(
        "Tasks of several objects", stamp,
        "The campaign's tasks (the tables above, if any, cover its single-label searches). "
        "Per slice, strategy and kind of task (all: one object of each label; any: one of "
        "any; count: every instance of one label). Task as expected: found what it asked for "
        "(every label, any one, the instances counted) with every report right, or gave up "
        "when the world lacks a label, k/n and % with a 95% Wilson interval, runs cut by "
        "the wall-clock budget left out (counted in 'wall cuts'). Labels found: over "
        "completed runs, the labels whose part ended found, of the labels asked (an any "
        "task's labels it did not need are left out and counted apart). False reports: "
        "reports naming an object that is not of their label, of all reports. Task sim "
        "time: the whole task's simulated time, median / p90 over completed runs.", "",
        "| slice | strategy | task | runs | task as expected | labels found | false reports "
        "| timeouts | wall cuts | failed | task sim time s |",
        "|---|---|---|---|---|---|---|---|---|---|---|")
    for name, part in slices(tasks):
        for strategy in strategies:
            for kind in kinds:
                mine = [r for r in part if r["strategy"] == strategy and r["task"] == kind]
                if not mine:
                    continue
                done = [r for r in mine if r["status"] == "ok"]
                lines.append("| " + " | ".join([
                    name, strategy, kind, str(len(mine)), percent_cell(comparable(mine)),
                    _labels_found(done), _false_reports(done), str(sum(map(is_timeout, mine))),
                    str(sum(r["status"] == WALL_CUT for r in mine)),
                    str(sum(map(is_failed, mine))), spread_cell(done, "sim_time_s", 0)]) + " |")
    return lines + [""]


def _labels_found(done: list[Row]) -> str:
    outcomes = [p.get("outcome") for r in done for p in parts(r)]
    asked = [o for o in outcomes if o != NOT_NEEDED]
    if not asked:
        return "--"
    found = sum(o == "found" for o in asked)
    spare = len(outcomes) - len(asked)
    return f"{found}/{len(asked)}" + (f" ({spare} not needed)" if spare else "")


def _false_reports(done: list[Row]) -> str:
    reports = sum(r.get("reports") or 0 for r in done)
    right = sum(r.get("reports_correct") or 0 for r in done)
    return f"{reports - right} of {reports}" if reports else "0"


def _label_table(tasks: list[Row], strategies: list[str], kinds: list[str], stamp: str
                 ) -> list[str]:
    lines = stamped(
        "Tasks: each label", stamp,
        "Each label's part of the tasks, over completed runs: found k/n and % with a 95% "
        "Wilson interval (n: the parts that were searched for, an any task's unneeded ones "
        "left out), how the others ended, reports naming a wrong object, and when the "
        "label's part ended (simulated s from the task's start, median over the parts "
        "found).", "",
        "| strategy | task | label | parts | found | gave up | timeout | not needed | false "
        "reports | ended at s (found) |",
        "|---|---|---|---|---|---|---|---|---|---|")
    for strategy in strategies:
        for kind in kinds:
            done = [r for r in tasks if r["strategy"] == strategy and r["task"] == kind
                    and r["status"] == "ok"]
            mine = [p for r in done for p in parts(r)]
            for label in sorted({str(p.get("label")) for p in mine}):
                of = [p for p in mine if str(p.get("label")) == label]
                outcome = [p.get("outcome") for p in of]
                asked = [o for o in outcome if o != NOT_NEEDED]
                times = [p["sim_time_s"] for p in of if p.get("outcome") == "found"
                         and isinstance(p.get("sim_time_s"), int | float)]
                wrong = sum((p.get("reports") or 0) - (p.get("correct_reports") or 0)
                            for p in of)
                lines.append("| " + " | ".join([
                    strategy, kind, label, str(len(of)),
                    _share(sum(o == "found" for o in asked), len(asked)),
                    str(outcome.count("gave_up")), str(outcome.count("timeout")),
                    str(outcome.count(NOT_NEEDED)), str(wrong), num(median(times), 0)]) + " |")
    return lines + [""]


def _share(k: int, n: int) -> str:
    interval = wilson(k, n)
    if interval is None:
        return "--"
    return (f"{k}/{n} = {100 * interval.estimate:.0f}% [{100 * interval.low:.0f}, "
            f"{100 * interval.high:.0f}]")


def _count_table(tasks: list[Row], strategies: list[str], stamp: str) -> list[str]:
    counts = [r for r in tasks if r["task"] == "count"]
    if not counts:
        return []
    lines = stamped(
        "Counting every instance", stamp,
        "Count tasks, over completed runs. Instances found: the distinct true instances the "
        "reports named, summed, of the true instances in the worlds, summed (scoring only: "
        "the robot never knows them); per run: the median of each run's share (runs whose "
        "world holds some). A stop is a run that ended on its own (found or gave up, not a "
        "timeout): correct stops left no instance unfound (k/n of the stops, 95% Wilson "
        "interval); early stops left some unfound.", "",
        "| slice | strategy | runs | instances found | per run | correct stops | early stops "
        "| timeouts | false reports |",
        "|---|---|---|---|---|---|---|---|---|")
    for name, part in slices(counts):
        for strategy in strategies:
            mine = [r for r in part if r["strategy"] == strategy]
            if not mine:
                continue
            done = [r for r in mine if r["status"] == "ok"]
            scored = [r for r in done if r.get("instances") is not None
                      and r.get("distinct") is not None]
            true = sum(r["instances"] for r in scored)
            named = sum(min(r["distinct"], r["instances"]) for r in scored)
            found = f"{named}/{true} = {100 * named / true:.0f}%" if true else "--"
            shares = [min(r["distinct"], r["instances"]) / r["instances"] for r in scored
                      if r["instances"] > 0]
            stops = [r for r in scored if r["outcome"] in ("found", "gave_up")]
            none_left = sum(r["distinct"] >= r["instances"] for r in stops)
            lines.append("| " + " | ".join([
                name, strategy, str(len(mine)), found, num(median(shares), 2),
                _share(none_left, len(stops)), str(len(stops) - none_left),
                str(sum(map(is_timeout, mine))), _false_reports(done)]) + " |")
    return lines + [""]


# ---- a task beside the single searches of its labels -------------------------------------


@dataclass(frozen=True)
class TaskAndSingles:
    """A task run (all or any) and the single-label runs of its labels, in the task's order,
    on the same scenario, world, robot, seed and strategy."""

    task: Row
    singles: tuple[Row, ...]

    @property
    def all_found(self) -> bool:
        """The task and every single search found what they asked for (with right reports)."""
        return all(r["status"] == "ok" and bool(r["success"]) and _timed(r)
                   for r in (self.task, *self.singles))


def _timed(row: Row) -> bool:
    return isinstance(row.get("sim_time_s"), int | float) and row["sim_time_s"] > 0


def _where(row: Row) -> tuple[Any, ...]:
    return (row["strategy"], row["scenario"], row["world"], row["robot"], row["seed"])


def task_and_singles(rows: Iterable[Row]) -> list[TaskAndSingles]:
    """Each all/any task run with its labels' single-label runs (same strategy, scenario,
    world, robot and seed), where the campaign ran every one of them and none was cut by
    the wall-clock budget."""
    rows = list(rows)
    singles = {(*_where(r), r["target"]): r for r in rows
               if not is_task(r) and r["status"] != WALL_CUT}
    out = []
    for row in rows:
        if row.get("task") not in RATIOS or row["status"] == WALL_CUT:
            continue
        labels = str(row.get("task_labels") or "").split()
        mine = [singles.get((*_where(row), label)) for label in labels]
        if labels and all(r is not None for r in mine):
            out.append(TaskAndSingles(row, tuple(r for r in mine if r is not None)))
    return out


def task_time_ratios(tuples: Iterable[TaskAndSingles]) -> dict[str, list[float]]:
    """Per tuple where the task and every single search found what they asked for: the
    task's simulated time / the sum of the singles' times (`sum`), / the shortest (`min`) and
    / the longest (`max`). An `all` task is read by `sum` (below 1: searching for the labels
    together was faster than one after another), an `any` task by `min` and `max` (below 1
    against the shortest: faster than searching for the label that turned out nearest)."""
    out: dict[str, list[float]] = {"sum": [], "min": [], "max": []}
    for t in tuples:
        if not t.all_found:
            continue
        times = [r["sim_time_s"] for r in t.singles]
        task = t.task["sim_time_s"]
        out["sum"].append(task / sum(times))
        out["min"].append(task / min(times))
        out["max"].append(task / max(times))
    return out


def singles_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Per slice, strategy and kind: the paired ratios of a task's time to its labels' single
    searches (none when the campaign did not run both)."""
    if not task_and_singles(rows):
        return []
    lines = stamped(
        "Tasks beside the single searches of their labels", stamp,
        "Tuples: a task run and the single-label searches of each of its labels on the same "
        "world, robot, seed and strategy, none cut by the wall-clock budget; all found: the "
        "tuples where the task and every single search found what they asked for (with right "
        "reports), over which the ratios are taken. Per tuple, the task's simulated time / "
        "the sum of the single searches' times (all: below 1, the joint search beat searching "
        "for the labels one after another), / the shortest and / the longest single time "
        "(any: below 1 against the shortest, it beat even the search for the label that "
        "turned out nearest); median with a 95% percentile-bootstrap interval (2,000 "
        "resamples, seeded) and the number of tuples.", "",
        "| slice | strategy | task | tuples | all found | task / sum of singles | task / "
        "shortest single | task / longest single |",
        "|---|---|---|---|---|---|---|---|")
    for name, part in slices(rows):
        tuples = task_and_singles(part)
        for strategy in strategies:
            for kind in RATIOS:
                mine = [t for t in tuples if t.task["strategy"] == strategy
                        and t.task["task"] == kind]
                if not mine:
                    continue
                ratios = task_time_ratios(mine)
                cells = [ratio_cell(ratios[r]) if r in RATIOS[kind] else "·"
                         for r in ("sum", "min", "max")]
                lines.append("| " + " | ".join([
                    name, strategy, kind, str(len(mine)),
                    str(sum(t.all_found for t in mine)), *cells]) + " |")
    return lines + [""]
