"""The report's planner tables: the DT sub-planner's part, and our numbers beside the paper's.

How often a strategy handed a search to the DT (POMDP) planner and what the DT decided; and,
for the office runs of Fig. 3 a-f, each scenario's outcome and the planner's own numbers
(plans, CP s/plan, DT calls, DT s/action) beside what the active visual search paper reports.
"""

from __future__ import annotations

from avs_planner.experiment.report_cells import band_cell, num, total
from avs_planner.experiment.report_header import stamped
from avs_planner.experiment.report_rows import Row
from avs_planner.experiment.stats import median

# Göbelbecker et al., Sec. 4: outcomes of Fig. 3 a-f; for a run like 3a, "14 plans
# in total, taking 0.2 - 0.5 seconds per plan on average", the DT planner "took about 0.5 - 2
# seconds per" action, and was called twice.
PAPER_OUTCOME = {"a": "found", "b": "found", "c": "gave_up", "d": "found", "e": "gave_up",
                 "f": "found"}
PAPER = ('Göbelbecker et al., "A Planning Approach to Active Visual Search in Large '
         'Environments"')


def dt_table(rows: list[Row], strategies: list[str], groups: list[str], stamp: str
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
    lines = stamped(
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
                     f"{num(median(calls), 1)} [{max(calls)}]" if calls else "--"]
            if decided:
                cells += [total(part, "dt_confirmed"), total(part, "dt_rejected")]
            lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]


def _share(k: int, n: int) -> str:
    """`k/n (p%)`, or `--` for no runs."""
    return f"{k}/{n} ({100 * k / n:.0f}%)" if n else "--"


def beside_the_paper(rows: list[Row], groups: list[str], stamp: str) -> list[str]:
    """Per scenario of Fig. 3 a-f: the paper's outcome beside our outcome counts, and the
    planner's numbers beside the paper's."""
    lines = stamped(
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
    return " | ".join(band_cell(rows, column, digits) for column, digits in (
        ("plans", 0), ("cp_s_per_plan", 3), ("dt_calls", 0), ("dt_s_per_action", 3)))
