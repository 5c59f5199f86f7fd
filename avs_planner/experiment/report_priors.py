"""The report's learned-priors section: a campaign's `priors` arms, default against learned.

A campaign with `priors: [default, learned]` (`priors.py`) runs every (world, target, strategy,
robot, noise seed) twice: on the knowledge file alone (`default`) and on the priors an
experience store learned, read without writing (`learned`). The section pairs the two runs
and gives per strategy and arm: found rates (Wilson), false reports, timeouts, failed runs,
simulated time, and the median of the per-pair ratios of simulated time, learned / default,
over the pairs where both found the target (seeded percentile-bootstrap interval; below 1:
the learned priors made the search faster); then the same per target label.
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
    is_timeout,
    time_ratios,
)

ARMS = ("default", "learned")


def is_priors_arm(row: Row) -> bool:
    """A run of a campaign's `priors` arms."""
    return row.get("priors") in ARMS


def priors_pairs(rows: list[Row], strategy: str) -> list[Pair]:
    """(learned, default) runs of one strategy on the same world, target, robot and noise
    seed, neither cut by the wall clock."""
    return arm_pairs(rows, strategy, "priors", ("learned", "default"),
                     lambda r: (r["scenario"], r["world"], r["target"], r["robot"], r["seed"]))


def priors_ratios(pairs: list[Pair]) -> list[float]:
    """Per-pair sim-time ratios learned / default where both found the target."""
    return time_ratios(pairs, "found")


def priors_tables(rows: list[Row], stamp: str) -> list[str]:
    """The learned-priors section; nothing when the campaign has no `priors` arms."""
    runs = [r for r in rows if is_priors_arm(r)]
    if not runs:
        return []
    strategies = list(dict.fromkeys(r["strategy"] for r in runs))
    arms = [a for a in ARMS if any(r["priors"] == a for r in runs)]
    lines = stamped(
        "Learned priors: default against learned", stamp,
        "Each (world, target, robot, noise seed) searched with the knowledge file's priors "
        "(default) and with the priors the experience store learned, read without writing "
        "(learned). Found: runs that found a present target, k/n and % with a 95% Wilson "
        "interval (wall cuts left out, failed runs counted as not found); false reports: "
        "reports naming something else; timeouts: the simulated budget spent; sim time: "
        "median / p90 over completed runs. Ratio learned / default: over the pairs where both "
        "found the target, the median of the per-pair simulated-time ratios, 95% "
        "percentile-bootstrap interval, (n pairs); below 1, the learned priors made the "
        "search faster.", "",
        "| strategy | priors | runs | found | false reports | timeouts | failed | sim time s "
        "| ratio learned / default |",
        "|---|---|---|---|---|---|---|---|---|")
    for strategy in strategies:
        mine = [r for r in runs if r["strategy"] == strategy]
        ratios = priors_ratios(priors_pairs(mine, strategy))
        for j, arm in enumerate(arms):
            these = comparable(r for r in mine if r["priors"] == arm)
            done = [r for r in these if r["status"] == "ok"]
            false = sum(bool(r["false_report"]) for r in done)
            ratio = ratio_cell(ratios) if j == 0 and len(arms) == 2 else ""
            lines.append(f"| {strategy} | {arm} | {len(these)} | {percent_cell(these)} | "
                         f"{false} | {sum(map(is_timeout, these))} | "
                         f"{sum(map(is_failed, these))} | {spread_cell(done, 'sim_time_s', 1)} "
                         f"| {ratio} |")
    lines.append("")
    if len(arms) == 2:
        lines += _by_target(runs, strategies, stamp)
    return lines


def _by_target(runs: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Found per arm and the ratio learned / default per target label."""
    lines = stamped(
        "Learned priors: by target", stamp,
        "Per strategy and target label: found k/n with the default and the learned priors, "
        "and the median learned / default ratio of simulated time over the pairs where both "
        "found the target.", "",
        "| strategy | target | found (default) | found (learned) | ratio learned / default |",
        "|---|---|---|---|---|")
    for strategy in strategies:
        mine = [r for r in runs if r["strategy"] == strategy]
        for target in sorted({r["target"] for r in mine}):
            part = [r for r in mine if r["target"] == target]
            default = comparable(r for r in part if r["priors"] == "default")
            learned = comparable(r for r in part if r["priors"] == "learned")
            lines.append(f"| {strategy} | {target} | {percent_cell(default)} | "
                         f"{percent_cell(learned)} | "
                         f"{ratio_cell(priors_ratios(priors_pairs(part, strategy)))} |")
    return lines + [""]
