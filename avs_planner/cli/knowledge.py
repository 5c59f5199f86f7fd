"""`avs knowledge show|export|reset --store PATH`: the priors learned from experience.

`show` prints what the store changes in the knowledge file (per rate it has counts for: the
file's value, the learned one and the counts; the category prior both ways); `export` every
count as plain data; `reset` forgets a building's counts (`--building`) or all of them.
Exit codes: 0 ok, 1 bad input (a missing or damaged store, a bad building id).
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from avs_planner.cli import EXIT_BAD_INPUT, EXIT_OK


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "knowledge", help="show, export or reset priors learned from experience",
        description="The experience store: counts of what finished episodes found, per "
        "building and for all buildings, from which episodes run with --experience take "
        "their priors (docs/learning.md).")
    parser.add_argument("action", choices=["show", "export", "reset"])
    parser.add_argument("--store", required=True, metavar="PATH",
                        help="the experience store (an SQLite file `avs simulate "
                        "--experience` wrote)")
    parser.add_argument("--building", metavar="ID", help="show: the priors for this building "
                        "(its counts over all buildings'); reset: forget only its own counts")
    parser.add_argument("--format", choices=["yaml", "json"], default="yaml",
                        help="output format of show and export (default yaml)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from conceptual_map.errors import ExperienceError, KnowledgeError
    from conceptual_map.knowledge import load_knowledge
    from conceptual_map.knowledge.experience import ExperienceStore, building_scope

    try:
        scope = building_scope(args.building) if args.building is not None else None
        with ExperienceStore(args.store, create=False) as store:
            if args.action == "reset":
                removed = store.reset(scope)
                print(f"reset {scope or 'every scope'} of {store.path.name}: {removed} "
                      f"row(s) removed")
                return EXIT_OK
            data = (store.export() if args.action == "export"
                    else store.show(load_knowledge(), args.building))
    except (ExperienceError, KnowledgeError) as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    _print(data, args.format)
    return EXIT_OK


def _print(data: dict[str, Any], fmt: str) -> None:
    if fmt == "json":
        print(json.dumps(data, indent=2))
        return
    import yaml

    print(yaml.safe_dump(data, sort_keys=False), end="")
