"""The report's outcome tables: how often each strategy ended as expected, and how they compare.

Per strategy (rates, timeouts, wall cuts, failures, times and counts); per slice of the
campaign, with paired time ratios against every other strategy; by scenario or world group;
and the paired comparisons (same world, target, robot and seed under two strategies): the mean
difference in ending as expected and the median per-pair ratios of simulated time to find a
present target and to give up on an absent one.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

from avs_planner.experiment.report_cells import (
    interval_cell,
    percent_cell,
    rate_cell,
    ratio_cell,
    spread_cell,
)
from avs_planner.experiment.report_header import stamped
from avs_planner.experiment.report_rows import (
    Row,
    as_expected,
    comparable,
    is_failed,
    is_present,
    is_timeout,
    pairs_of,
    runs_by_key,
    slices,
    time_ratios,
)
from avs_planner.experiment.results import WALL_CUT
from avs_planner.experiment.stats import bootstrap


def strategy_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Per strategy: outcome rates and counts, then times and counts over completed runs."""
    lines = stamped(
        "Per strategy", stamp,
        "Found: found the target, among runs whose target is in the world (or whose outcome "
        "is unknown); correct give-up: gave up, among runs whose target is absent; both with "
        "95% Wilson intervals, over the runs not cut by the wall-clock budget. False reports: "
        "reported an object that is not the target. Timeouts: the strategy spent its "
        "simulated time budget. Wall cuts: the episode ran out of wall-clock time (not "
        "comparable; rerun them). Failed: crashed, killed or raised. Times and counts are "
        "median / p90 over completed runs; CP s/plan and DT s/action are each run's mean.", "",
        "| strategy | runs | found | correct give-up | false reports | timeouts | wall cuts "
        "| failed | sim time s | distance m | plans | CP s/plan | DT s/action |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for strategy in strategies:
        mine = [r for r in rows if r["strategy"] == strategy]
        done = [r for r in mine if r["status"] == "ok"]
        lines.append("| " + " | ".join([
            strategy, str(len(mine)), *_outcome_cells(mine, rate_cell),
            *(spread_cell(done, c, d) for c, d in (("sim_time_s", 0), ("distance_m", 1),
                                                   ("plans", 0), ("cp_s_per_plan", 3),
                                                   ("dt_s_per_action", 3)))]) + " |")
    return lines + [""]


def _outcome_cells(rows: list[Row], rate: Callable[[list[Row]], str]) -> list[str]:
    """found, correct give-up, false reports, timeouts, wall cuts, failed."""
    fair = comparable(rows)
    return [rate([r for r in fair if is_present(r)]),
            rate([r for r in fair if not is_present(r)]),
            str(sum(r["status"] == "ok" and bool(r["false_report"]) for r in rows)),
            str(sum(map(is_timeout, rows))), str(sum(r["status"] == WALL_CUT for r in rows)),
            str(sum(map(is_failed, rows)))]


def targets_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Per slice and strategy: found and correct give-ups (k/n, %), and the paired time
    ratios against every other strategy."""
    others = strategies if len(strategies) > 1 else []
    absent = any(not is_present(r) for r in rows)
    head = ["slice", "strategy", "found", "correct give-ups", "false reports", "timeouts",
            "wall cuts", "failed"]
    head += [f"time to find vs {b}" for b in others]
    head += [f"time to give up vs {b}" for b in others] if absent else []
    lines = stamped(
        "Targets: found, give-ups and paired time ratios", stamp,
        "Per slice of the campaign (all runs, then each robot and each world group when there "
        "are several). Found: k/n of the present targets, % with a 95% Wilson interval; "
        "correct give-ups: the same on absent targets; runs cut by the wall-clock budget are "
        "left out of both and counted in 'wall cuts'. Time to find vs B: over the pairs (same "
        "world, target, robot and seed) where both this strategy and B found the target, the "
        "median of the per-pair ratios of simulated time (this / B; below 1: this one is "
        "faster), with a 95% percentile-bootstrap interval (2,000 resamples, seeded) and the "
        "number of pairs; time to give up vs B: the same over absent targets where both gave "
        "up.", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head))
    for name, part in slices(rows):
        by_key = runs_by_key(part)
        for a in strategies:
            mine = [r for r in part if r["strategy"] == a]
            if not mine:
                continue
            cells = [name, a, *_outcome_cells(mine, percent_cell)]
            for kind in ("found", "gave_up")[:1 + absent]:
                cells += ["·" if b == a
                          else ratio_cell(time_ratios(pairs_of(by_key, a, b), kind))
                          for b in others]
            lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]


def group_table(rows: list[Row], groups: list[str], strategies: list[str], stamp: str
                ) -> list[str]:
    """Per world group (a scenario, or a generated style): runs ending as expected."""
    lines = stamped("By scenario or world group", stamp,
                    "Runs ending as expected (found, or gave up on an absent target), 95% "
                    "Wilson interval; runs cut by the wall-clock budget left out.", "",
                    "| group | " + " | ".join(strategies) + " |",
                    "|---|" + "---|" * len(strategies))
    fair = comparable(rows)
    for group in groups:
        cells = [rate_cell([r for r in fair if r["group"] == group and r["strategy"] == s])
                 for s in strategies]
        lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return lines + [""]


def paired_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Every two strategies, per slice: the paired difference in ending as expected and the
    paired time ratios (none for a one-strategy campaign)."""
    if len(strategies) < 2:
        return []
    lines = stamped(
        "Paired comparisons", stamp,
        "Pairs: the same world, target, robot and seed under two strategies, neither cut by "
        "the wall-clock budget. As expected A - B: mean of (A as expected) - (B as expected), "
        "over all pairs. Time to find A/B: median of the per-pair ratios of simulated time "
        "over present targets both found (below 1: A faster), and how often A was faster; "
        "time to give up A/B: the same over absent targets where both gave up. 95% "
        "percentile-bootstrap intervals (2,000 resamples, seeded: the same table gives the "
        "same report).", "",
        "| slice | A | B | pairs | as expected A - B | both found | time to find A/B | A "
        "faster | both gave up | time to give up A/B |",
        "|---|---|---|---|---|---|---|---|---|---|")
    for name, part in slices(rows):
        by_key = runs_by_key(part)
        for a, b in itertools.combinations(strategies, 2):
            pairs = pairs_of(by_key, a, b)
            if not pairs:
                continue
            success = bootstrap([float(as_expected(x)) - float(as_expected(y))
                                 for x, y in pairs])
            found, gave_up = time_ratios(pairs, "found"), time_ratios(pairs, "gave_up")
            faster = sum(ratio < 1.0 for ratio in found)
            lines.append(f"| {name} | {a} | {b} | {len(pairs)} | {interval_cell(success, 2)} | "
                         f"{len(found)} | {ratio_cell(found)} | {faster}/{len(found)} | "
                         f"{len(gave_up)} | {ratio_cell(gave_up)} |")
    return lines + [""]
