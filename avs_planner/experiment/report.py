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

This module reads the table and puts the report together: its sections in order, the plots
beside it (`plots.py`) and the runs that failed. The parts live in their own modules:
`report_rows.py` (which runs count, slices and pairs), `report_cells.py` (numbers with their
intervals, as table cells; the statistics themselves: `stats.py`), `report_header.py` (the
header and every section's stamp), `report_outcomes.py` (the outcome and comparison tables),
`report_planner.py` (the DT sub-planner, and beside the paper), `report_map.py` (map
quality), `report_tasks.py` (tasks of several objects: in a campaign with tasks, the other
tables cover its single-label searches and the tasks have sections of their own) and
`report_sequences.py` (campaign sequences: memory on against memory off) and
`report_priors.py` (learned priors: the default arm against the learned one).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.plots import sim_time_plot, success_plot
from avs_planner.experiment.report_header import campaign_stamp, header
from avs_planner.experiment.report_map import map_table
from avs_planner.experiment.report_outcomes import (
    group_table,
    paired_table,
    strategy_table,
    targets_table,
)
from avs_planner.experiment.report_planner import PAPER, PAPER_OUTCOME, beside_the_paper, dt_table
from avs_planner.experiment.report_priors import priors_tables
from avs_planner.experiment.report_rows import Pair, Row, as_expected, comparable, normalised
from avs_planner.experiment.report_sequences import sequence_tables
from avs_planner.experiment.report_tasks import is_task, task_tables
from avs_planner.experiment.results import RESULTS_FILE, WALL_CUT, read_results

__all__ = ["PAPER", "PAPER_OUTCOME", "Pair", "Row", "as_expected", "build_report", "comparable",
           "render"]


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
    """The report's Markdown for `rows`; its plots are drawn beside `out`. The tables of
    single-label searches cover the runs of one label; tasks of several objects have their
    own sections (`report_tasks.py`)."""
    every = [normalised(r) for r in rows]
    stamp = campaign_stamp(every, meta)
    lines = header(every, meta)
    rows = [r for r in every if not is_task(r)]
    if rows:
        strategies = list(dict.fromkeys(r["strategy"] for r in rows))  # the campaign's order
        groups = sorted({r["group"] for r in rows})
        lines += strategy_table(rows, strategies, stamp)
        lines += targets_table(rows, strategies, stamp)
        lines += group_table(rows, groups, strategies, stamp)
        lines += paired_table(rows, strategies, stamp)
        lines += dt_table(rows, strategies, groups, stamp)
        lines += map_table(rows, strategies, stamp)
        if {r["scenario"] for r in rows} <= set(PAPER_OUTCOME) and rows[0]["scenario"]:
            lines += beside_the_paper(rows, groups, stamp)
    lines += task_tables(every, stamp)
    lines += sequence_tables(every, stamp)
    lines += priors_tables(every, stamp)
    if rows:
        lines += _figures(rows, groups, strategies, out)
    lines += _failures(every)
    return "\n".join(lines) + "\n"


# ---- plots and failures ------------------------------------------------------------------


def _figures(rows: list[Row], groups: list[str], strategies: list[str], out: Path
             ) -> list[str]:
    """The plots (`plots.py`), drawn beside `out`, and the Markdown that shows them."""
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
    """The runs that did not complete (the first `shown`), with their error or reason."""
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
