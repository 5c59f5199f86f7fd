"""`build_report`: a Markdown report of a campaign's results table, with statistics and plots.

Rates carry 95% Wilson intervals; paired comparisons (same world, target, robot and seed under
two strategies) carry seeded percentile-bootstrap intervals: the mean difference in ending as
expected, and the median of the per-pair ratios of simulated time, to find a present target
(both found it) and to give up on an absent one (both gave up). A run that crashed, was killed
or raised counts as not successful; a run cut by its wall-clock budget (`wall_cut`: the
machine, not the strategy) is left out of rates and pairs and counted on its own. Results are
broken down by robot and by world group when a campaign has several. Every section is stamped
with the campaign's dates and git commit (`provenance.py`). For the office runs of Fig. 3 a-f
a table puts our numbers beside the paper's.
"""

from __future__ import annotations

import functools
import itertools
import json
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.plots import sim_time_plot, success_plot
from avs_planner.experiment.provenance import UNKNOWN, describe
from avs_planner.experiment.results import RESULTS_FILE, WALL_CUT, is_wall_cut, read_results
from avs_planner.experiment.stats import Interval, bootstrap, median, quantile, wilson

Row = dict[str, Any]
Pair = tuple[Row, Row]
# Göbelbecker et al., Sec. 4: outcomes of Fig. 3 a-f; for a run like 3a, "14 plans
# in total, taking 0.2 - 0.5 seconds per plan on average", the DT planner "took about 0.5 - 2
# seconds per" action, and was called twice.
PAPER_OUTCOME = {"a": "found", "b": "found", "c": "gave_up", "d": "found", "e": "gave_up",
                 "f": "found"}
PAPER = ('Göbelbecker et al., "A Planning Approach to Active Visual Search in Large '
         'Environments"')
_VERDICT_COLUMNS = ("correct", "success", "correct_give_up", "false_report")


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
    rows = [_normalised(r) for r in rows]
    strategies = list(dict.fromkeys(r["strategy"] for r in rows))  # the campaign's order
    groups = sorted({r["group"] for r in rows})
    stamp = _stamp(rows, meta)
    lines = _header(rows, meta)
    lines += _strategy_table(rows, strategies, stamp)
    lines += _targets_table(rows, strategies, stamp)
    lines += _group_table(rows, groups, strategies, stamp)
    lines += _paired(rows, strategies, stamp)
    lines += _dt_table(rows, strategies, groups, stamp)
    lines += _map_table(rows, strategies, stamp)
    if {r["scenario"] for r in rows} <= set(PAPER_OUTCOME) and rows[0]["scenario"]:
        lines += _beside_the_paper(rows, groups, stamp)
    lines += _figures(rows, groups, strategies, out)
    lines += _failures(rows)
    return "\n".join(lines) + "\n"


def _normalised(row: Row) -> Row:
    """A table written before wall cuts had their own status records them as `ok`."""
    if row["status"] == "ok" and is_wall_cut(row.get("outcome"), row.get("reason")):
        return {**row, "status": WALL_CUT, **dict.fromkeys(_VERDICT_COLUMNS)}
    return row


def as_expected(row: Row) -> bool:
    """Found the target (or, for an absent target, gave up); failed runs are not successes."""
    if row["status"] != "ok":
        return False
    if row["expected"] == "gave_up":
        return bool(row["correct_give_up"])
    return bool(row["success"])


def comparable(rows: Iterable[Row]) -> list[Row]:
    """The runs a strategy answers for: all but those cut by the wall-clock budget."""
    return [r for r in rows if r["status"] != WALL_CUT]


def _failed(row: Row) -> bool:
    return row["status"] not in ("ok", WALL_CUT)


def _present(row: Row) -> bool:
    return row["expected"] != "gave_up"


def _timeout(row: Row) -> bool:
    """The strategy used up its simulated time budget (a completed run)."""
    return row["status"] == "ok" and row["outcome"] == "timeout"


# ---- provenance --------------------------------------------------------------------------


def _stamp(rows: list[Row], meta: dict[str, Any]) -> str:
    """`campaign X, run 2026-11-27 to 2026-11-28, commit abc1234`: what every number is of."""
    return f"Campaign {meta.get('name', '?')}, run {_dates(meta)}, commit {_commits(rows, meta)}."


def _dates(meta: dict[str, Any]) -> str:
    days = sorted({str(run.get(key))[:10] for run in meta.get("invocations", [])
                   for key in ("started", "finished") if run.get(key)})
    if not days:
        return "on an unrecorded date"
    return days[0] if len(days) == 1 else f"{days[0]} to {days[-1]}"


def _commits(rows: list[Row], meta: dict[str, Any]) -> str:
    """The commits the runs were made at (the `commit` column; else what each `run` noted)."""
    commits = {r.get("commit") for r in rows if r.get("commit")}
    if not commits:
        commits = {describe(run) for run in meta.get("invocations", [])
                   if "commit" in run and run.get("ran")}
    if not commits:
        return f"{UNKNOWN} (not recorded)"
    known = sorted(c for c in commits if c != UNKNOWN)
    if not known:
        return UNKNOWN
    text = ", ".join(known) + (f", {UNKNOWN}" if UNKNOWN in commits else "")
    if len(commits) > 1:
        text += " (mixed: results.csv's `commit` column says which run is which)"
    if any(c.endswith("+dirty") for c in known):
        text += " (+dirty: tracked files differed from the commit)"
    return text


def _stamped(title: str, stamp: str, *text: str) -> list[str]:
    return [f"## {title}", "", f"_{stamp}_", "", *text]


# ---- header ------------------------------------------------------------------------------


def _header(rows: list[Row], meta: dict[str, Any]) -> list[str]:
    ok = sum(r["status"] == "ok" for r in rows)
    wall = sum(r["status"] == WALL_CUT for r in rows)
    overhead = median([r["overhead_s"] for r in rows if r["overhead_s"] is not None])
    episode = sum(r["episode_s"] or 0.0 for r in rows)
    lines = [f"# Campaign report: {meta.get('name', '?')}", ""]
    if meta.get("description"):
        lines += [str(meta["description"]), ""]
    lines += [f"- {_stamp(rows, meta)}",
              f"- runs recorded: {len(rows)} of {meta.get('runs', '?')}; completed {ok}, cut "
              f"by the wall-clock budget {wall}, crashed/timed out/failed "
              f"{len(rows) - ok - wall}",
              f"- episode wall time, summed: {episode:.0f} s; median scheduling overhead per "
              f"episode (wall time outside the episode): {_num(overhead, 3)} s"]
    for run in meta.get("invocations", []):
        commit = f" at commit {describe(run)}" if "commit" in run else ""
        lines.append(f"- `avs experiment run` finished {run.get('finished')}{commit}: "
                     f"{run.get('ran')} episodes ({run.get('failed')} failed) on "
                     f"{run.get('backend')} x{run.get('workers')} in {run.get('wall_s')} s")
    if wall:
        lines.append(f"- {wall} runs were cut by the wall-clock budget (a loaded machine): "
                     "they are left out of every rate and comparison below; `avs experiment "
                     "run ... --retry-failed` runs them again")
    return lines + [""]


# ---- per strategy ------------------------------------------------------------------------


def _strategy_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    lines = _stamped(
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
            strategy, str(len(mine)), *_outcome_cells(mine, _rate),
            *(_spread(done, c, d) for c, d in (("sim_time_s", 0), ("distance_m", 1),
                                               ("plans", 0), ("cp_s_per_plan", 3),
                                               ("dt_s_per_action", 3)))]) + " |")
    return lines + [""]


def _outcome_cells(rows: list[Row], rate: Callable[[list[Row]], str]) -> list[str]:
    """found, correct give-up, false reports, timeouts, wall cuts, failed."""
    fair = comparable(rows)
    return [rate([r for r in fair if _present(r)]), rate([r for r in fair if not _present(r)]),
            str(sum(r["status"] == "ok" and bool(r["false_report"]) for r in rows)),
            str(sum(map(_timeout, rows))), str(sum(r["status"] == WALL_CUT for r in rows)),
            str(sum(map(_failed, rows)))]


def _rate(rows: list[Row]) -> str:
    k = sum(map(as_expected, rows))
    interval = wilson(k, len(rows))
    if interval is None:
        return "--"
    return f"{interval.estimate:.2f} [{interval.low:.2f}, {interval.high:.2f}] ({k}/{len(rows)})"


def _percent(rows: list[Row]) -> str:
    k = sum(map(as_expected, rows))
    interval = wilson(k, len(rows))
    if interval is None:
        return "--"
    return (f"{k}/{len(rows)} = {100 * interval.estimate:.0f}% [{100 * interval.low:.0f}, "
            f"{100 * interval.high:.0f}]")


def _spread(rows: list[Row], column: str, digits: int) -> str:
    values = [r[column] for r in rows if r[column] is not None]
    if not values:
        return "--"
    return f"{_num(median(values), digits)} / {_num(quantile(values, 0.9), digits)}"


# ---- targets, by slice -------------------------------------------------------------------


def _slices(rows: list[Row]) -> list[tuple[str, list[Row]]]:
    """All runs, then each robot and each world group when the campaign has several."""
    out = [("all", rows)]
    robots = sorted({_robot(r) for r in rows})
    groups = sorted({r["group"] for r in rows})
    if len(robots) > 1:
        out += [(f"robot {x}", [r for r in rows if _robot(r) == x]) for x in robots]
    if len(groups) > 1:
        out += [(f"group {g}", [r for r in rows if r["group"] == g]) for g in groups]
    return out


def _robot(row: Row) -> str:
    return row["robot"] or "world's own"


def _targets_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    others = strategies if len(strategies) > 1 else []
    absent = any(not _present(r) for r in rows)
    head = ["slice", "strategy", "found", "correct give-ups", "false reports", "timeouts",
            "wall cuts", "failed"]
    head += [f"time to find vs {b}" for b in others]
    head += [f"time to give up vs {b}" for b in others] if absent else []
    lines = _stamped(
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
    for name, part in _slices(rows):
        by_key = _by_key(part)
        for a in strategies:
            mine = [r for r in part if r["strategy"] == a]
            if not mine:
                continue
            cells = [name, a, *_outcome_cells(mine, _percent)]
            for kind in ("found", "gave_up")[:1 + absent]:
                cells += ["·" if b == a else _ratio_cell(_ratios(_pairs(by_key, a, b), kind))
                          for b in others]
            lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]


def _by_key(rows: list[Row]) -> dict[tuple[Any, ...], Row]:
    return {(r["strategy"], *_pair_key(r)): r for r in rows}


def _pair_key(row: Row) -> tuple[Any, ...]:
    return row["scenario"], row["world"], row["target"], row["robot"], row["seed"]


def _pairs(by_key: dict[tuple[Any, ...], Row], a: str, b: str) -> list[Pair]:
    """(A's run, B's run) on the same (world, target, robot, seed), neither cut by the wall
    clock."""
    return [(row, by_key[(b, *key[1:])]) for key, row in by_key.items()
            if key[0] == a and (b, *key[1:]) in by_key
            and WALL_CUT not in (row["status"], by_key[(b, *key[1:])]["status"])]


def _ratios(pairs: list[Pair], kind: str) -> list[float]:
    """Per-pair sim-time ratios A/B: `found` where both found a present target, `gave_up`
    where both gave up on an absent one."""
    def ended(row: Row) -> bool:
        if row["status"] != "ok" or not row["sim_time_s"] or row["sim_time_s"] <= 0:
            return False
        if kind == "found":
            return _present(row) and bool(row["success"])
        return not _present(row) and row["outcome"] == "gave_up"

    return [x["sim_time_s"] / y["sim_time_s"] for x, y in pairs if ended(x) and ended(y)]


@functools.lru_cache(maxsize=1024)
def _median_interval(values: tuple[float, ...]) -> Interval | None:
    """The median with its bootstrap interval (a slice's ratios recur in two tables)."""
    return bootstrap(values, _median)


def _median(values: Sequence[float]) -> float:
    return float(median(values) or 0.0)


def _ratio_cell(ratios: list[float]) -> str:
    interval = _median_interval(tuple(ratios))
    if interval is None:
        return "--"
    return (f"{interval.estimate:.2f} [{interval.low:.2f}, {interval.high:.2f}] "
            f"(n {len(ratios)})")


# ---- by group ----------------------------------------------------------------------------


def _group_table(rows: list[Row], groups: list[str], strategies: list[str], stamp: str
                 ) -> list[str]:
    lines = _stamped("By scenario or world group", stamp,
                     "Runs ending as expected (found, or gave up on an absent target), 95% "
                     "Wilson interval; runs cut by the wall-clock budget left out.", "",
                     "| group | " + " | ".join(strategies) + " |",
                     "|---|" + "---|" * len(strategies))
    fair = comparable(rows)
    for group in groups:
        cells = [_rate([r for r in fair if r["group"] == group and r["strategy"] == s])
                 for s in strategies]
        lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return lines + [""]


# ---- paired comparisons ------------------------------------------------------------------


def _paired(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    if len(strategies) < 2:
        return []
    lines = _stamped(
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
    for name, part in _slices(rows):
        by_key = _by_key(part)
        for a, b in itertools.combinations(strategies, 2):
            pairs = _pairs(by_key, a, b)
            if not pairs:
                continue
            success = bootstrap([float(as_expected(x)) - float(as_expected(y))
                                 for x, y in pairs])
            found, gave_up = _ratios(pairs, "found"), _ratios(pairs, "gave_up")
            faster = sum(ratio < 1.0 for ratio in found)
            lines.append(f"| {name} | {a} | {b} | {len(pairs)} | {_interval(success, 2)} | "
                         f"{len(found)} | {_ratio_cell(found)} | {faster}/{len(found)} | "
                         f"{len(gave_up)} | {_ratio_cell(gave_up)} |")
    return lines + [""]


def _interval(interval: Interval | None, digits: int) -> str:
    if interval is None:
        return "--"
    return (f"{interval.estimate:+.{digits}f} [{interval.low:+.{digits}f}, "
            f"{interval.high:+.{digits}f}]")


# ---- the DT sub-planner ------------------------------------------------------------------


def _dt_table(rows: list[Row], strategies: list[str], groups: list[str], stamp: str
              ) -> list[str]:
    """How often the switching planner handed a search to the DT, and what the DT decided."""
    users = [s for s in strategies if s == "switching" or any(
        (r["dt_calls"] or 0) > 0 for r in rows if r["strategy"] == s)]
    if not users:
        return []
    decided = any(r.get("dt_confirmed") is not None or r.get("dt_rejected") is not None
                  for r in rows)
    head = ["strategy", "group", "completed runs", "runs with DT", "DT calls",
            "DT calls per run with DT"] + (["confirmed", "rejected"] if decided else [])
    lines = _stamped(
        "The DT sub-planner", stamp,
        "Completed runs in which the strategy called the DT (POMDP) planner at least once, the "
        "DT calls in all, and their median [max] per run that called it"
        + ("; confirmed / rejected: the DT's verdicts (where the episode's summary records "
           "them)." if decided else "."), "",
        "| " + " | ".join(head) + " |", "|" + "---|" * len(head))
    for strategy in users:
        for group in [*groups, "all"] if len(groups) > 1 else groups:
            part = [r for r in rows if r["strategy"] == strategy and r["status"] == "ok"
                    and group in ("all", r["group"])]
            calls = [r["dt_calls"] for r in part if r["dt_calls"]]
            cells = [strategy, group, str(len(part)), _share(len(calls), len(part)),
                     str(sum(calls)),
                     f"{_num(median(calls), 1)} [{max(calls)}]" if calls else "--"]
            if decided:
                cells += [_total(part, "dt_confirmed"), _total(part, "dt_rejected")]
            lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]


def _share(k: int, n: int) -> str:
    return f"{k}/{n} ({100 * k / n:.0f}%)" if n else "--"


def _total(rows: list[Row], column: str) -> str:
    values = [r.get(column) for r in rows if r.get(column) is not None]
    return str(int(sum(values))) if values else "--"


# ---- map quality -------------------------------------------------------------------------


def _map_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Room-map scores, where the episodes' summaries carry them (`map_score`)."""
    scored = [r for r in rows if r["status"] == "ok" and any(
        r.get(c) is not None for c in ("map_rooms_true", "map_category_accuracy"))]
    if not scored:
        return []
    lines = _stamped(
        "Map quality", stamp,
        "Over completed runs whose summary scores the room map: rooms matched, summed over "
        "runs, of the true rooms, summed (a search that ends early never sees some rooms), "
        "and of the true rooms the robot entered; merges and splits (a mapped room covering "
        "several true ones, a true room mapped as several), summed; room-category accuracy "
        "weighted by the area the robot entered (sum of accuracy x entered area / sum of entered "
        "area); the entered area, median per run.", "",
        "| slice | strategy | runs scored | rooms matched | of rooms entered | merges | splits "
        "| category accuracy (area-weighted) | entered m² per run |",
        "|---|---|---|---|---|---|---|---|---|")
    for name, part in _slices(scored):
        for strategy in strategies:
            mine = [r for r in part if r["strategy"] == strategy]
            if mine:
                lines.append(f"| {name} | {strategy} | {len(mine)} | {_matched(mine)} | "
                             f"{_matched(mine, 'map_entered_rooms', 'map_entered_matched')} | "
                             f"{_total(mine, 'map_merges')} | {_total(mine, 'map_splits')} | "
                             f"{_accuracy(mine)} | "
                             f"{_num(median(_values(mine, 'map_entered_area_m2')), 1)} |")
    return lines + [""]


def _values(rows: list[Row], column: str) -> list[float]:
    return [r[column] for r in rows if r.get(column) is not None]


def _matched(rows: list[Row], of: str = "map_rooms_true",
             matched_column: str = "map_rooms_matched") -> str:
    """Rooms matched (`matched_column`), summed over runs, of `of`, summed."""
    both = [r for r in rows if r.get(of) is not None and r.get(matched_column) is not None]
    true = sum(r[of] for r in both)
    if not true:
        return "--"
    matched = sum(r[matched_column] for r in both)
    return f"{matched:g}/{true:g} = {100 * matched / true:.0f}%"


def _accuracy(rows: list[Row]) -> str:
    both = [r for r in rows if r.get("map_category_accuracy") is not None
            and (r.get("map_entered_area_m2") or 0) > 0]
    area = sum(r["map_entered_area_m2"] for r in both)
    if not area:
        return "--"
    weighted = sum(r["map_category_accuracy"] * r["map_entered_area_m2"] for r in both)
    return f"{100 * weighted / area:.0f}% (over {area:.0f} m²)"


# ---- beside the paper (Fig. 3 a-f) -------------------------------------------------------


def _beside_the_paper(rows: list[Row], groups: list[str], stamp: str) -> list[str]:
    lines = _stamped(
        f"Beside the paper: {PAPER}, Fig. 3 a-f", stamp,
        "The paper reports one run per scenario: its outcome, and for a run like 3a 14 plans "
        "at 0.2-0.5 s per plan (CP), 2 DT calls and 0.5-2 s per DT action. Ours: outcome "
        "counts over the seeds, then median [p10-p90] over completed runs.", "",
        "| scenario | paper outcome | ours: found / gave up / timeout / failed | "
        "plans (paper 14 in 3a) | CP s/plan (paper 0.2-0.5) | DT calls (paper 2 in 3a) "
        "| DT s/action (paper 0.5-2) |", "|---|---|---|---|---|---|---|")
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


# ---- plots and failures ------------------------------------------------------------------


def _figures(rows: list[Row], groups: list[str], strategies: list[str], out: Path
             ) -> list[str]:
    stem = out.with_suffix("")
    key, names = ("strategy", strategies) if len(strategies) > 1 else ("group", groups)
    drawn = [(f"Simulated time per {key}",
              sim_time_plot([r for r in rows if r["status"] == "ok"], key, names,
                            Path(f"{stem}-sim-time.png"))),
             ("Success by scenario or world group",
              success_plot(comparable(rows), groups, strategies, as_expected,
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
    lines = ["## Failed and wall-cut runs", "", "| run | status | error |", "|---|---|---|"]
    for r in failed[:shown]:
        text = r["error"] or (r.get("reason") if r["status"] == WALL_CUT else "")
        error = str(text or "").replace("|", "\\|").replace("\n", " ")[:160]
        lines.append(f"| {r['run_id']} | {r['status']} | {error} |")
    if len(failed) > shown:
        lines.append(f"| ... | | {len(failed) - shown} more in results.csv |")
    return lines + [""]


def _num(value: float | None, digits: int) -> str:
    return "--" if value is None else f"{value:.{digits}f}"
