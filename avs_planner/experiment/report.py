"""`build_report`: a Markdown report of a campaign's results table, with statistics and plots.

Rates carry 95% Wilson intervals; paired comparisons (same world, target, robot and seed under
two strategies) carry seeded percentile-bootstrap intervals. A run that crashed, timed out or
failed counts as not successful. For the seed's office runs (scenarios a-f) a table puts our
numbers beside the paper's.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.plots import sim_time_plot, success_plot
from avs_planner.experiment.results import RESULTS_FILE, read_results
from avs_planner.experiment.stats import Interval, bootstrap, median, quantile, wilson

Row = dict[str, Any]
# Seed 003 (Göbelbecker et al.), Sec. 4: outcomes of Fig. 3 a-f; for a run like 3a, "14 plans
# in total, taking 0.2 - 0.5 seconds per plan on average", the DT planner "took about 0.5 - 2
# seconds per" action, and was called twice.
PAPER_OUTCOME = {"a": "found", "b": "found", "c": "gave_up", "d": "found", "e": "gave_up",
                 "f": "found"}


def build_report(run_dir: Path, out: Path) -> Path:
    """Write the report for `run_dir/results.csv` to `out` (plots beside it)."""
    table = run_dir / RESULTS_FILE
    if not table.exists():
        raise CampaignError(f"{run_dir}: no {RESULTS_FILE}; run `avs experiment run` first")
    rows = read_results(table)
    if not rows:
        raise CampaignError(f"{table}: no runs recorded yet")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(render(rows, _meta(run_dir), out), encoding="utf-8")
    return out


def _meta(run_dir: Path) -> dict[str, Any]:
    try:
        return json.loads((run_dir / "campaign.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {"name": run_dir.name}


def render(rows: list[Row], meta: dict[str, Any], out: Path) -> str:
    strategies = sorted({r["strategy"] for r in rows})
    groups = sorted({r["group"] for r in rows})
    lines = _header(rows, meta)
    lines += _strategy_table(rows, strategies)
    lines += _group_table(rows, groups, strategies)
    lines += _paired(rows, strategies)
    if {r["scenario"] for r in rows} <= set(PAPER_OUTCOME) and rows[0]["scenario"]:
        lines += _seed003(rows, groups)
    lines += _figures(rows, groups, strategies, out)
    lines += _failures(rows)
    return "\n".join(lines) + "\n"


def as_expected(row: Row) -> bool:
    """Found the target (or, for an absent target, gave up); failed runs are not successes."""
    if row["status"] != "ok":
        return False
    if row["expected"] == "gave_up":
        return bool(row["correct_give_up"])
    return bool(row["success"])


def _header(rows: list[Row], meta: dict[str, Any]) -> list[str]:
    failed = [r for r in rows if r["status"] != "ok"]
    overhead = median([r["overhead_s"] for r in rows if r["overhead_s"] is not None])
    episode = sum(r["episode_s"] or 0.0 for r in rows)
    lines = [f"# Campaign report: {meta.get('name', '?')}", ""]
    if meta.get("description"):
        lines += [str(meta["description"]), ""]
    lines += [f"- runs recorded: {len(rows)} of {meta.get('runs', '?')}; completed "
              f"{len(rows) - len(failed)}, crashed/timed out/failed {len(failed)}",
              f"- episode wall time, summed: {episode:.0f} s; median scheduling overhead per "
              f"episode (wall time outside the episode): {_num(overhead, 3)} s"]
    for run in meta.get("invocations", []):
        lines.append(f"- `avs experiment run` finished {run.get('finished')}: {run.get('ran')} "
                     f"episodes ({run.get('failed')} failed) on {run.get('backend')} x"
                     f"{run.get('workers')} in {run.get('wall_s')} s")
    return lines + [""]


def _strategy_table(rows: list[Row], strategies: list[str]) -> list[str]:
    lines = ["## Per strategy", "",
             "Success: found the target, among runs whose target is in the world (or whose "
             "outcome is unknown); correct give-up: gave up, among runs whose target is "
             "absent; both with 95% Wilson intervals. False reports: reported an object that "
             "is not the target. Times and counts are median / p90 over completed runs; CP "
             "s/plan and DT s/action are each run's mean.", "",
             "| strategy | runs | success | correct give-up | false reports | failed runs "
             "| sim time s | distance m | plans | CP s/plan | DT s/action |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for strategy in strategies:
        mine = [r for r in rows if r["strategy"] == strategy]
        present = [r for r in mine if r["expected"] != "gave_up"]
        absent = [r for r in mine if r["expected"] == "gave_up"]
        done = [r for r in mine if r["status"] == "ok"]
        lines.append("| " + " | ".join([
            strategy, str(len(mine)), _rate(present), _rate(absent),
            str(sum(bool(r["false_report"]) for r in done)),
            str(len(mine) - len(done)),
            *(_spread(done, c, d) for c, d in (("sim_time_s", 0), ("distance_m", 1),
                                               ("plans", 0), ("cp_s_per_plan", 3),
                                               ("dt_s_per_action", 3)))]) + " |")
    return lines + [""]


def _rate(rows: list[Row]) -> str:
    interval = wilson(sum(as_expected(r) for r in rows), len(rows))
    if interval is None:
        return "--"
    return (f"{interval.estimate:.2f} [{interval.low:.2f}, {interval.high:.2f}] "
            f"({sum(as_expected(r) for r in rows)}/{len(rows)})")


def _spread(rows: list[Row], column: str, digits: int) -> str:
    values = [r[column] for r in rows if r[column] is not None]
    if not values:
        return "--"
    return f"{_num(median(values), digits)} / {_num(quantile(values, 0.9), digits)}"


def _group_table(rows: list[Row], groups: list[str], strategies: list[str]) -> list[str]:
    lines = ["## By scenario or world group", "",
             "Runs ending as expected (found, or gave up on an absent target), 95% Wilson "
             "interval.", "", "| group | " + " | ".join(strategies) + " |",
             "|---|" + "---|" * len(strategies)]
    for group in groups:
        cells = [_rate([r for r in rows if r["group"] == group and r["strategy"] == s])
                 for s in strategies]
        lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return lines + [""]


def _paired(rows: list[Row], strategies: list[str]) -> list[str]:
    if len(strategies) < 2:
        return []
    lines = ["## Paired comparisons", "",
             "Pairs: the same world, target, robot and seed under two strategies. Success "
             "difference: mean of (A as expected) - (B as expected); sim time difference: "
             "mean of A - B over pairs where both ended as expected; 95% percentile-bootstrap "
             "intervals (2,000 resamples, seeded).", "",
             "| A | B | pairs | success A - B | both ok | sim time A - B (s) | A faster |",
             "|---|---|---|---|---|---|---|"]
    by_key = {(r["strategy"], _pair_key(r)): r for r in rows}
    for a, b in itertools.combinations(strategies, 2):
        pairs = [(r, by_key[(b, k)]) for (s, k), r in by_key.items()
                 if s == a and (b, k) in by_key]
        both = [(x, y) for x, y in pairs if as_expected(x) and as_expected(y)
                and x["sim_time_s"] is not None and y["sim_time_s"] is not None]
        success = bootstrap([float(as_expected(x)) - float(as_expected(y)) for x, y in pairs])
        time = bootstrap([x["sim_time_s"] - y["sim_time_s"] for x, y in both])
        faster = sum(x["sim_time_s"] < y["sim_time_s"] for x, y in both)
        lines.append(f"| {a} | {b} | {len(pairs)} | {_interval(success, 2)} | {len(both)} | "
                     f"{_interval(time, 1)} | {faster}/{len(both)} |")
    return lines + [""]


def _pair_key(row: Row) -> tuple[Any, ...]:
    return row["scenario"], row["world"], row["target"], row["robot"], row["seed"]


def _interval(interval: Interval | None, digits: int) -> str:
    if interval is None:
        return "--"
    return (f"{interval.estimate:+.{digits}f} [{interval.low:+.{digits}f}, "
            f"{interval.high:+.{digits}f}]")


def _seed003(rows: list[Row], groups: list[str]) -> list[str]:
    lines = ["## Beside the seed paper (003, Fig. 3 a-f)", "",
             "The paper reports one run per scenario: its outcome, and for a run like 3a 14 "
             "plans at 0.2-0.5 s per plan (CP), 2 DT calls and 0.5-2 s per DT action. Ours: "
             "outcome counts over the seeds, then median [p10-p90] over completed runs.", "",
             "| scenario | paper outcome | ours: found / gave up / timeout / failed | "
             "plans (paper 14 in 3a) | CP s/plan (paper 0.2-0.5) | DT calls (paper 2 in 3a) "
             "| DT s/action (paper 0.5-2) |", "|---|---|---|---|---|---|---|"]
    for group in groups:
        mine = [r for r in rows if r["group"] == group]
        done = [r for r in mine if r["status"] == "ok"]
        counts = "/".join(str(sum(r["outcome"] == o for r in done))
                          for o in ("found", "gave_up", "timeout"))
        lines.append(f"| {group} | {PAPER_OUTCOME.get(group, '?')} | {counts} / "
                     f"{len(mine) - len(done)} (of {len(mine)}) | "
                     f"{_paper_columns(done)} |")
    lines.append(f"| all | | | {_paper_columns([r for r in rows if r['status'] == 'ok'])} |")
    return lines + [""]


def _paper_columns(rows: list[Row]) -> str:
    return " | ".join(_band(rows, column, digits) for column, digits in (
        ("plans", 0), ("cp_s_per_plan", 3), ("dt_calls", 0), ("dt_s_per_action", 3)))


def _band(rows: list[Row], column: str, digits: int) -> str:
    values = [r[column] for r in rows if r[column] is not None]
    if not values:
        return "--"
    return (f"{_num(median(values), digits)} [{_num(quantile(values, 0.1), digits)}-"
            f"{_num(quantile(values, 0.9), digits)}]")


def _figures(rows: list[Row], groups: list[str], strategies: list[str], out: Path
             ) -> list[str]:
    stem = out.with_suffix("")
    key, names = ("strategy", strategies) if len(strategies) > 1 else ("group", groups)
    drawn = [(f"Simulated time per {key}",
              sim_time_plot([r for r in rows if r["status"] == "ok"], key, names,
                            Path(f"{stem}-sim-time.png"))),
             ("Success by scenario or world group",
              success_plot(rows, groups, strategies, as_expected,
                           Path(f"{stem}-success.png")))]
    lines = ["## Plots", ""]
    for title, path in drawn:
        if path is not None:
            lines += [f"![{title}]({path.name})", ""]
    return lines if len(lines) > 2 else []


def _failures(rows: Sequence[Row], shown: int = 20) -> list[str]:
    failed = [r for r in rows if r["status"] != "ok"]
    if not failed:
        return []
    lines = ["## Failed runs", "", "| run | status | error |", "|---|---|---|"]
    for r in failed[:shown]:
        error = str(r["error"] or "").replace("|", "\\|").replace("\n", " ")[:160]
        lines.append(f"| {r['run_id']} | {r['status']} | {error} |")
    if len(failed) > shown:
        lines.append(f"| ... | | {len(failed) - shown} more in results.csv |")
    return lines + [""]


def _num(value: float | None, digits: int) -> str:
    return "--" if value is None else f"{value:.{digits}f}"

