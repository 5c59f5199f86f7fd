"""`avs world generate`: write a generated floor plan (world-file YAML) for a seed and a style."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

_EXIT_OK = 0
_EXIT_BAD_INPUT = 1
_STYLES = ("office", "apartment", "lab")  # sim.generate.STYLES; not imported at parser time
_TABLES = ("default", "moved")  # sim.generation.table.TABLES (a test checks they agree)


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser("world", help="generated worlds: floor plans for a seed")
    commands = parser.add_subparsers(dest="world_command", metavar="WORLD_COMMAND", required=True)
    generate = commands.add_parser(
        "generate", help="write a generated world file (same seed and options, same file)",
        description="Generate a building from a seed: an office (rooms off a corridor), an "
        "apartment or a lab, with furniture and objects placed by the knowledge's priors (a "
        "share placed where the priors say unlikely), written as a world file that `avs "
        "simulate --world FILE` and `avs sim check` read. The same seed and options give the "
        "same file. Seeds 10000 and up are the held-out evaluation range "
        "(docs/experiments.md).")
    generate.add_argument("--seed", type=int, required=True, help="non-negative integer")
    generate.add_argument("--style", default="office", choices=_STYLES,
                          help="building style (default: office)")
    generate.add_argument("--rooms", type=int, default=None,
                          help="rooms off the corridor/hall (default: drawn per style)")
    generate.add_argument("--surprise", type=float, default=0.25,
                          help="share of small objects placed where priors say unlikely "
                               "(default: 0.25)")
    generate.add_argument("--robot", default="pioneer", choices=("pioneer", "pr2"),
                          help="robot model written to the file (default: pioneer)")
    generate.add_argument("--day", type=int, default=0,
                          help="the building this many days later: small objects moved, doors "
                               "toggled (default: 0, the building as generated)")
    generate.add_argument("--move", type=float, default=0.2,
                          help="per day, the probability each small object moves to another "
                               "placement (default: 0.2)")
    generate.add_argument("--doors", type=float, default=0.0,
                          help="per day, the probability each door toggles open/closed; every "
                               "room stays reachable (default: 0)")
    generate.add_argument("--table", default="default", choices=_TABLES,
                          help="placement table: default, or moved (cups, books and staplers "
                               "kept elsewhere than the knowledge expects: "
                               "sim/generation/placement-moved.yaml; default: default)")
    generate.add_argument("--out", help="YAML file to write (default: standard output)")
    generate.set_defaults(func=run_generate)


def run_generate(args: argparse.Namespace) -> int:
    from sim.errors import SimError
    from sim.generate import generate_world

    try:
        world = generate_world(args.seed, args.style, args.rooms, args.surprise, args.robot,
                               args.day, args.move, args.doors, args.table)
        world.spec()  # every generated world passes sim's own checks; say so if one does not
    except SimError as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return _EXIT_BAD_INPUT
    text = world.yaml()
    if not args.out:
        sys.stdout.write(text)
        return _EXIT_OK
    out = Path(args.out)
    try:
        out.write_text(text, encoding="utf-8")
    except OSError as exc:
        print(f"avs: error: cannot write {out}: {exc.strerror or exc}", file=sys.stderr)
        return _EXIT_BAD_INPUT
    data = world.data
    print(f"wrote {out}: {data['name']}, {len(data['rooms'])} rooms, {len(data['doors'])} doors, "
          f"{len(data['furniture'])} furniture, {len(data['objects'])} objects "
          f"({len(world.surprises)} placed unusually)")
    return _EXIT_OK
