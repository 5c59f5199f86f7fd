"""`avs experiment run|report|list`: campaigns of many episodes, and their statistics.

`run` executes every episode of a campaign not yet done in --out (so a stopped campaign
continues where it stopped), on a local process pool or a Ray cluster, with a progress line on
stderr, and writes results.csv (noting the git commit it ran at). `report` turns that into a
Markdown report with plots. `list` shows the built-in campaigns, the held-out ones included.
Exit codes: 0 ok (failed episodes are recorded, not fatal), 1 bad input, 130 interrupted.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "experiment", help="run campaigns of episodes and report their statistics",
        description="Experiment campaigns: worlds x targets x strategies x robots x seeds.")
    sub = parser.add_subparsers(dest="experiment_command", metavar="ACTION", required=True)
    _register_run(sub)
    _register_report(sub)
    listing = sub.add_parser(
        "list", help="list the built-in campaigns and their sizes",
        description="List the built-in campaigns (avs_planner/experiment/campaigns/): name, "
        "number of episodes, what they run. `heldout` and `heldout-fig3` are the evaluation-"
        "only range; `development` is their twin on development seeds (docs/experiments.md).")
    listing.set_defaults(func=run_list)


def _register_run(sub: Any) -> None:
    run = sub.add_parser(
        "run", help="run a campaign's episodes (skipping those already done in --out)",
        description="Run one episode per (world, target, strategy, robot, seed), each in its "
                    "own process. Runs already recorded in --out are skipped.")
    run.add_argument("campaign", help="built-in campaign name (see `avs experiment list`) or "
                     "a campaign YAML path")
    run.add_argument("--out", required=True, type=Path, help="output directory")
    run.add_argument("--backend", choices=["local", "ray"], default="local")
    run.add_argument("--workers", type=int, help="episodes at a time (default: CPUs of this "
                     "machine, or of the Ray cluster)")
    run.add_argument("--address", help="Ray cluster address (default: start Ray locally)")
    run.add_argument("--retry-failed", action="store_true",
                     help="run again the episodes recorded as crashed, timed out, failed or "
                     "cut by the wall-clock budget (status wall_cut)")
    run.add_argument("--limit", type=int, help="run at most N episodes now, then stop")
    run.add_argument("--experience", type=Path, metavar="PATH",
                     help="the experience store for every episode that uses one, instead of "
                     "the campaign's `experience.store` (relative to --out); e.g. the store a "
                     "training campaign wrote (docs/learning.md)")
    run.add_argument("--json", action="store_true", help="print the final counts as JSON")
    run.set_defaults(func=run_campaign_command)


def _register_report(sub: Any) -> None:
    report = sub.add_parser(
        "report", help="write a Markdown report (tables, confidence intervals, plots)",
        description="Build a Markdown report from DIR/results.csv; plots go beside it.")
    report.add_argument("dir", type=Path, help="a campaign output directory")
    report.add_argument("--out", type=Path, help="report file (default DIR/report.md)")
    report.set_defaults(func=run_report)


def run_campaign_command(args: argparse.Namespace) -> int:
    from avs_planner.experiment import load_campaign
    from avs_planner.experiment.runner import RunOptions, run_campaign

    if args.limit is not None and args.limit < 0:
        print("avs: error: --limit must be at least 0", file=sys.stderr)
        return 1
    campaign = load_campaign(args.campaign)
    options = RunOptions(args.out, args.backend, args.workers, args.address,
                         args.retry_failed, args.limit, experience=args.experience)
    line = _ProgressLine(sys.stderr.isatty())
    try:
        result = run_campaign(campaign, options, line)
    finally:
        line.finish()
    progress = result.progress
    overhead = statistics.median(progress.overheads) if progress.overheads else None
    counts = {"campaign": campaign.name, "total": progress.total, "done": progress.done,
              "ran_now": progress.ran, "failed": progress.failed, "backend": result.backend,
              "workers": result.slots, "wall_s": round(result.wall_s, 1),
              "median_overhead_s": None if overhead is None else round(overhead, 3),
              "results": str(result.results)}
    if args.json:
        print(json.dumps(counts, indent=2))
    else:
        text = "--" if overhead is None else f"{overhead:.3f} s"
        print(f"{campaign.name}: {progress.done}/{progress.total} runs done ({progress.ran} now, "
              f"{progress.failed} failed) on {result.backend} x{result.slots} in "
              f"{result.wall_s:.1f} s; median scheduling overhead {text} per episode")
        print(f"  results: {result.results}")
    return 0


def run_report(args: argparse.Namespace) -> int:
    from avs_planner.experiment.report import build_report

    out = args.out or args.dir / "report.md"
    path = build_report(args.dir, out)
    print(f"wrote {path}")
    return 0


def run_list(args: argparse.Namespace) -> int:
    from avs_planner.experiment.campaign import builtin_campaigns, load_campaign

    for name in builtin_campaigns():
        try:
            campaign = load_campaign(name)
            size = f"{len(campaign.runs())} runs"
        except Exception as exc:  # noqa: BLE001 - one broken campaign must not hide the rest
            campaign, size = None, f"not available: {exc}"
        description = campaign.description if campaign is not None else ""
        print(f"{name:20s} {size:12s} {description}")
    return 0


class _ProgressLine:
    """The campaign's progress on stderr: rewritten in place on a terminal, else one line
    per finished episode."""

    def __init__(self, tty: bool):
        self.tty = tty
        self.shown = False

    def __call__(self, progress: Any) -> None:
        text = progress.line()
        if self.tty:
            print("\r" + text.ljust(100), end="", file=sys.stderr, flush=True)
        else:
            print(text, file=sys.stderr, flush=True)
        self.shown = True

    def finish(self) -> None:
        if self.shown and self.tty:
            print(file=sys.stderr)
