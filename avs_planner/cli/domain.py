"""`avs domain check DOMAIN [PROBLEM ...] [--json]`: lint PDDL for knowledge engineers."""

from __future__ import annotations

import argparse
import json
import sys


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add `avs domain` and its `check` subcommand."""
    domain = subparsers.add_parser("domain", help="work with PDDL domains")
    actions = domain.add_subparsers(dest="domain_command", metavar="ACTION", required=True)
    parser = actions.add_parser(
        "check",
        help="lint a domain and its problems",
        description="Report mistakes as FILE:LINE:COL: error|warning: message. "
        "Exit 0 when there are no errors, 1 otherwise (with --strict, warnings count as "
        "errors).",
    )
    parser.add_argument("domain", help="the domain file")
    parser.add_argument("problems", nargs="*", help="problem files to check with it")
    parser.add_argument("--json", action="store_true", help="print a JSON list of findings")
    parser.add_argument("--strict", action="store_true",
                        help="treat warnings as errors (e.g. an undeclared requirement, which "
                        "`avs plan` accepts as Fast Downward does)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Print the findings; exit 1 if any is an error."""
    from avs_planner.pddl import check

    diagnostics = check(args.domain, args.problems)
    if args.strict:
        diagnostics = [d.as_error() for d in diagnostics]
    if args.json:
        print(json.dumps([d.to_dict() for d in diagnostics], indent=2))
    else:
        for diagnostic in diagnostics:
            print(diagnostic, file=sys.stdout)
        errors = sum(d.is_error for d in diagnostics)
        warnings = len(diagnostics) - errors
        print(f"{errors} error(s), {warnings} warning(s)", file=sys.stderr)
    return 1 if any(d.is_error for d in diagnostics) else 0
