"""The report's memory section: campaign sequences run with the robot's memory on and off.

A campaign sequence (`sequences.py`) runs a building's tasks day after day; its arms differ
only in whether the robot remembers the building between tasks. Task 0 of both arms starts
with nothing remembered, so its pairs are a control (their ratio should be about 1); from
task 1 on, the memory arm may know where things were. The section pairs the arms' runs of the
same building, task index, strategy, robot and noise seed, and gives per strategy: found rates
(Wilson) and false reports per arm, over tasks from 1 on and over task 0, and the median of the
per-pair ratios of simulated time, memory on / off, over the pairs where both found the target
(seeded percentile-bootstrap interval; below 1: memory made it faster).
"""

from __future__ import annotations

from avs_planner.experiment.report_cells import percent_cell, ratio_cell, spread_cell
from avs_planner.experiment.report_header import stamped
from avs_planner.experiment.report_rows import (
    Pair,
    Row,
    arm_pairs,
    comparable,
    is_failed,
    time_ratios,
)


def is_sequence(row: Row) -> bool:
    """A task of a campaign sequence run with memory on or off."""
    return row.get("memory") in ("on", "off")


def memory_pairs(rows: list[Row], strategy: str) -> list[Pair]:
    """(memory on, memory off) runs of one strategy on the same building, task index, robot
    and noise seed, neither cut by the wall clock."""
    return arm_pairs(rows, strategy, "memory", ("on", "off"),
                     lambda r: (r["world"], r["task_index"], r["robot"], r["seed"]))


def memory_ratios(pairs: list[Pair]) -> list[float]:
    """Per-pair sim-time ratios on / off where both found the target."""
    return time_ratios(pairs, "found")


def sequence_tables(rows: list[Row], stamp: str) -> list[str]:
    """The memory section; nothing when the campaign has no sequences."""
    runs = [r for r in rows if is_sequence(r)]
    if not runs:
        return []
    strategies = list(dict.fromkeys(r["strategy"] for r in runs))
    arms = [a for a in ("on", "off") if any(r["memory"] == a for r in runs)]
    lines = stamped(
        "Memory: tasks on later days of a building", stamp,
        "Campaign sequences: each building's tasks in order, task i on day i (small objects "
        "moved, doors toggled between days), with the robot's memory of the building on or "
        "off. Found: runs that found the target, k/n and % with a 95% Wilson interval (wall "
        "cuts left out, failed runs counted as not found); false reports: reports naming "
        "something else; sim time: median / p90 over completed runs. Ratio on / off: over the "
        "pairs (same building, task index, robot, noise seed) where both found the target, "
        "the median of the per-pair simulated-time ratios, 95% percentile-bootstrap "
        "interval, (n pairs); below 1, memory made the search faster. Task 0 starts with "
        "nothing remembered in either arm: a control.", "",
        "| strategy | tasks | memory | runs | found | false reports | failed | sim time s "
        "| ratio on / off |",
        "|---|---|---|---|---|---|---|---|---|")
    for strategy in strategies:
        mine = [r for r in runs if r["strategy"] == strategy]
        for name, keep in (("≥ 1", lambda i: i is not None and i >= 1),
                           ("0", lambda i: i == 0)):
            part = [r for r in mine if keep(r["task_index"])]
            if not part:
                continue
            ratios = memory_ratios(memory_pairs(part, strategy))
            for j, arm in enumerate(arms):
                these = comparable(r for r in part if r["memory"] == arm)
                false = sum(bool(r["false_report"]) for r in these if r["status"] == "ok")
                ratio = ratio_cell(ratios) if j == 0 and len(arms) == 2 else ""
                done = [r for r in these if r["status"] == "ok"]
                lines.append(f"| {strategy} | {name} | {arm} | {len(these)} | "
                             f"{percent_cell(these)} | {false} | "
                             f"{sum(map(is_failed, these))} | "
                             f"{spread_cell(done, 'sim_time_s', 1)} | {ratio} |")
    lines.append("")
    lines += _by_index(runs, strategies, stamp)
    return lines


def _by_index(runs: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """The ratio on / off and found counts per task index (how memory pays as days pass)."""
    if not any(r["memory"] == "on" for r in runs) or not any(r["memory"] == "off"
                                                            for r in runs):
        return []
    lines = stamped(
        "Memory: by task index", stamp,
        "Per strategy and task index: found k/n with memory on and off, and the median "
        "on / off ratio of simulated time over the pairs where both found the target.", "",
        "| strategy | task | found (on) | found (off) | ratio on / off |",
        "|---|---|---|---|---|")
    for strategy in strategies:
        mine = [r for r in runs if r["strategy"] == strategy]
        for index in sorted({r["task_index"] for r in mine if r["task_index"] is not None}):
            part = [r for r in mine if r["task_index"] == index]
            on = comparable(r for r in part if r["memory"] == "on")
            off = comparable(r for r in part if r["memory"] == "off")
            lines.append(f"| {strategy} | {index} | {percent_cell(on)} | {percent_cell(off)} | "
                         f"{ratio_cell(memory_ratios(memory_pairs(part, strategy)))} |")
    return lines + [""]
