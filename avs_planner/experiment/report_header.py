"""What every number of a campaign report is of: its header and the stamp on every section.

The header counts the runs recorded, completed, cut by the wall-clock budget and failed, and
lists each `avs experiment run`; the stamp names the campaign, the dates it ran and the git
commits its runs were made at (`provenance.py`).
"""

from __future__ import annotations

from typing import Any

from avs_planner.experiment.provenance import UNKNOWN, describe
from avs_planner.experiment.report_cells import num
from avs_planner.experiment.report_rows import Row
from avs_planner.experiment.results import WALL_CUT
from avs_planner.experiment.stats import median


def campaign_stamp(rows: list[Row], meta: dict[str, Any]) -> str:
    """`campaign X, run 2026-11-27 to 2026-11-28, commit abc1234`: what every number is of."""
    return f"Campaign {meta.get('name', '?')}, run {_dates(meta)}, commit {_commits(rows, meta)}."


def _dates(meta: dict[str, Any]) -> str:
    """The days the campaign's invocations started and finished on."""
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


def stamped(title: str, stamp: str, *text: str) -> list[str]:
    """A section's heading, its stamp, then `text`: every table says what it is of."""
    return [f"## {title}", "", f"_{stamp}_", "", *text]


def header(rows: list[Row], meta: dict[str, Any]) -> list[str]:
    """The report's title and what was run: runs recorded, completed, cut and failed, wall
    time, and each `avs experiment run` of the campaign."""
    ok = sum(r["status"] == "ok" for r in rows)
    wall = sum(r["status"] == WALL_CUT for r in rows)
    overhead = median([r["overhead_s"] for r in rows if r["overhead_s"] is not None])
    episode = sum(r["episode_s"] or 0.0 for r in rows)
    lines = [f"# Campaign report: {meta.get('name', '?')}", ""]
    if meta.get("description"):
        lines += [str(meta["description"]), ""]
    lines += [f"- {campaign_stamp(rows, meta)}",
              f"- runs recorded: {len(rows)} of {meta.get('runs', '?')}; completed {ok}, cut "
              f"by the wall-clock budget {wall}, crashed/timed out/failed "
              f"{len(rows) - ok - wall}",
              f"- episode wall time, summed: {episode:.0f} s; median scheduling overhead per "
              f"episode (wall time outside the episode): {num(overhead, 3)} s"]
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
