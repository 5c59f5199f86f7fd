"""`avs domain check DOMAIN [PROBLEM ...] [--json]`: lint PDDL for knowledge engineers."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # unified-planning loads with the reader: import it when the command runs
    from avs_planner.pddl import Diagnostic


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add `avs domain` and its `check` subcommand."""
    domain = subparsers.add_parser("domain", help="work with PDDL domains")
    actions = domain.add_subparsers(dest="domain_command", metavar="ACTION", required=True)
    parser = actions.add_parser(
        "check",
        help="lint a domain and its problems",
        description="Report mistakes as FILE:LINE:COL: error|warning: message. "
        "A problem without errors is also read and grounded as `avs plan` does, so what the "
        "planner refuses there is reported too. Exit 0 when there are no errors, 1 otherwise "
        "(with --strict, warnings count as errors).",
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
    diagnostics += _grounding(args.domain, args.problems, diagnostics)
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


def _grounding(domain: str, problems: list[str], found: list[Diagnostic]) -> list[Diagnostic]:
    """What `avs plan` refuses past the checks, found by reading and grounding each problem
    the checks passed (e.g. more state-dependent effect conditions than a ground action may
    have: that depends on the objects), at the action's or goal's position."""
    from avs_planner.cp.grounding import grounding_diagnostics
    from avs_planner.errors import PddlError
    from avs_planner.pddl import Diagnostic, read_files

    failed = {d.file for d in found if d.is_error}
    if domain in failed:
        return []
    extra: list[Diagnostic] = []
    for problem in problems:
        if problem in failed:
            continue
        try:
            extra += grounding_diagnostics(read_files(domain, problem))
        except PddlError as exc:  # what unified-planning's reader refuses
            extra.append(Diagnostic.from_error(exc, "unsupported"))
    return extra
