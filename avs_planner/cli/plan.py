"""`avs plan DOMAIN PROBLEM`: plan with the continual planner and print the plan or JSON."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the planner loads unified-planning: import it only when the command runs
    from avs_planner.cp.search import PlanResult

# Exit code per PlanStatus value.
EXIT_CODES = {
    "solved": 0,
    "unsolvable": 2,
    "no_plan_above_threshold": 2,
    "timeout": 3,
    "node_limit": 3,
}


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "plan",
        help="plan a (probabilistic) PDDL problem",
        description="Find a plan minimising c(pi) + R(1 - p(pi)) (Goebelbecker et al., A Planning "
        "Approach to Active Visual Search in Large Environments). Reads PDDL 2.1 (STRIPS, "
        "ADL, action costs) with derived predicates (:derived), any goal formula (or, "
        "exists, imply, ... compiled into a derived predicate) and PPDDL's single-outcome "
        "probabilistic effects; domains/README.md has the details. Exit codes: "
        "0 solved, 1 bad input, 2 unsolvable / no plan with p > 0 (or above --min-success), "
        "3 timeout or node limit with no plan found yet (with one found, the best so far is "
        "printed, exit 0, and `stopped_by` says which limit ended the search).",
    )
    parser.add_argument("domain", help="domain PDDL file")
    parser.add_argument("problem", help="problem PDDL file")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--reward", type=float, default=None,
                        help="goal reward R (default 500)")
    parser.add_argument("--weight", type=float, default=None,
                        help="weight w >= 1 on the remaining cost estimate (1: A*; default 2); "
                        "picks the weighted mode")
    parser.add_argument("--timeout", type=float, default=None,
                        help="seconds for the whole planning call: reading, grounding and "
                        "search (default: none). No search starts once it has passed and a "
                        "search running then stops within one expansion; grounding is not "
                        "interrupted, so one that alone takes longer ends the call with no "
                        "plan (exit 3). With it the default mode is anytime")
    parser.add_argument("--node-limit", type=int, default=None, help="max expanded states")
    parser.add_argument("--patience", type=_patience, default=None,
                        help="once a plan is found, expansions without a better one before "
                        "the best is returned ('inf': no limit; default 2500 with an "
                        "inadmissible heuristic, no limit with hmax)")
    parser.add_argument("--mode", choices=("auto", "anytime", "weighted"), default="auto",
                        help="anytime: greedy best-first with FF and helpful actions (LAMA's "
                        "first iteration), then weighted A* restarts with w = 5, 3, 2, 1; "
                        "prints the best plan by objective at --timeout, or before it when "
                        "the last restart ends or one runs out of memory (no restart "
                        "proves its plan optimal: FF is inadmissible, so only the end of the "
                        "schedule stops it early); "
                        "probabilistic objectives kept. weighted: one weighted "
                        "A* search (with --heuristic hmax and --weight 1, optimal). auto (the "
                        "default): anytime when a --timeout bounds it and neither --weight "
                        "nor --heuristic is given, else weighted (the restarts down to w = 1 "
                        "have no bound of their own)")
    parser.add_argument("--anytime", action="store_true", help="the same as --mode anytime")
    parser.add_argument("--heuristic", default=None,
                        help="hmax (admissible), hadd, ff (default) or blind; picks the "
                        "weighted mode")
    parser.add_argument("--min-success", type=float, default=0.0,
                        help="give up if the best plan's success probability is below this")
    parser.add_argument("--engine", choices=("auto", "native", "python"), default="auto",
                        help="search core: native (compiled, same results), python, or auto "
                        "(native when built; default)")
    parser.add_argument("--threads", type=int, choices=(1, 2), default=None,
                        help="threads the native core evaluates states on (same results; "
                        "default: 2 for large tasks on a machine with 2+ CPUs, else 1)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from avs_planner.cp.deadline import Deadline
    from avs_planner.cp.planner import plan
    from avs_planner.cp.search import SearchOptions
    from avs_planner.pddl import read_files

    deadline = Deadline.from_now(args.timeout)  # reading the files counts too
    given = {"reward": args.reward, "weight": args.weight}
    options = SearchOptions(
        heuristic=args.heuristic or "ff", timeout_s=args.timeout, node_limit=args.node_limit,
        min_success=args.min_success, engine=args.engine, patience=args.patience,
        threads=args.threads, anytime=_anytime(args),
        **{k: v for k, v in given.items() if v is not None},
    ).check()
    pproblem = read_files(args.domain, args.problem)
    for warning in pproblem.warnings:
        print(warning, file=sys.stderr)
    try:
        result = plan(pproblem, options, deadline=deadline)
    except MemoryError:
        print(f"avs plan: out of memory after {deadline.elapsed():.1f} s with no plan found; "
              "bound the search with --timeout (the anytime mode then returns its first "
              "plan) or --node-limit", file=sys.stderr)
        return EXIT_CODES["node_limit"]
    print(json.dumps(result.as_json()) if args.json else _text(result))
    if result.status.value == "timeout" and args.timeout is not None:
        print(f"avs plan: no plan within {args.timeout:g} s", file=sys.stderr)
    hint = _limit_hint(result, options.heuristic)
    if hint:
        print(hint, file=sys.stderr)
    return EXIT_CODES[result.status.value]


def _anytime(args: argparse.Namespace) -> bool:
    """`--mode`: auto is anytime when a timeout bounds it and no option of the weighted
    search (a weight, a heuristic) was asked for."""
    mode = "anytime" if args.anytime else args.mode
    if mode == "auto":
        return (args.timeout is not None and args.weight is None and args.heuristic is None)
    return mode == "anytime"


def _limit_hint(result: PlanResult, heuristic: str) -> str | None:
    """What to try when a limit stopped a search that had no helpful actions: hadd and hmax
    time out (10 s) on the 20-place AVS problems, where ff needs 4-37 expansions."""
    if result.status.value not in ("timeout", "node_limit"):
        return None
    if heuristic in ("ff", "blind"):
        return None
    return (f"avs plan: no plan within the limit with --heuristic {heuristic}; ff (the "
            f"default) picks helpful actions first and often needs far fewer expansions")


def _patience(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value >= 0 or (math.isfinite(value) and value != int(value)):
        raise argparse.ArgumentTypeError(f"expected a whole number of expansions >= 0 or "
                                         f"'inf', got {text!r}")
    return value


def _text(result: PlanResult) -> str:
    lines = [step.label for step in result.plan]
    if not result.solved:
        lines.append(f"; status: {result.status.value}")
    if result.stopped_by:
        lines.append(f"; stopped by: {result.stopped_by} (the best plan found so far)")
    lines += [
        f"; cost: {result.cost:g}",
        f"; probability: {result.probability:.6g}",
        f"; objective: {result.objective:.6g}" if math.isfinite(result.objective)
        else "; objective: none",
        f"; planning time: {result.planning_time_s:.4f} s",
        f"; expanded: {result.expanded}",
    ]
    return "\n".join(lines)
