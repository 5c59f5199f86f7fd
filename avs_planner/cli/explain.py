"""`avs explain RUN_DIR`: why an episode went as it did (the assumption ledger, in words)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from avs_planner.cli import EXIT_BAD_INPUT, EXIT_OK


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "explain", help="explain an episode: its assumptions, replans and why it ended",
        description="Print the explanation of an episode's output folder: every assumption "
        "its plans used (probability when first assumed and later, confirmed or refuted by "
        "which observation), the reason for every replan, and for a give-up the room "
        "hypotheses tried with their final probabilities. Reads RUN_DIR/explanation.json, or "
        "rebuilds it from RUN_DIR/trace.jsonl.")
    parser.add_argument("run_dir", metavar="RUN_DIR", help="an episode's output folder "
                        "(`avs simulate --out`, a campaign's runs/<id>, a task's folder)")
    parser.add_argument("--json", action="store_true", help="print the explanation as JSON")
    parser.add_argument("--rebuild", action="store_true", help="rebuild it from trace.jsonl "
                        "even when explanation.json exists (the rebuilt one lacks the final "
                        "beliefs, which only the finished episode knew)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from avs_planner.reporting.explain import ExplainError, load, render

    try:
        explanation = load(Path(args.run_dir), rebuild=args.rebuild)
    except ExplainError as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.json:
        print(json.dumps(explanation, indent=2, default=str))
    else:
        print(render(explanation), end="")
    return EXIT_OK
