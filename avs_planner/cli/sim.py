"""`avs sim render` and `avs sim check`: look at and validate world files."""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # sim pulls in pybullet and matplotlib: import them only when a command runs
    from sim.world_spec import WorldSpec

_EXIT_OK = 0
_EXIT_BAD_INPUT = 1


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser("sim", help="simulated worlds: render and check world files")
    commands = parser.add_subparsers(dest="sim_command", metavar="SIM_COMMAND", required=True)
    worlds = ", ".join(_builtin_world_names())
    render = commands.add_parser(
        "render", help="draw a world top-down to a PNG",
        description="Draw a world file (or a built-in world) top-down to a PNG: walls, doors, "
        "rooms with their categories, furniture and objects, and the robot's start. This is "
        "the world's truth, as the experimenter sees it; the robot never does.")
    render.add_argument("--world", required=True, help=f"built-in name ({worlds}) or YAML path")
    render.add_argument("--out", help="PNG to write (default: WORLDNAME.png)")
    render.set_defaults(func=run_render)
    check = commands.add_parser(
        "check", help="validate a world file and summarise it",
        description="Read a world file (or a built-in world), check it and build it once in "
        "the simulator (its fields, the robot's start, room categories the knowledge knows), "
        "and print a one-line summary: size, rooms, doors, furniture, objects, robot "
        "(--json: the full summary). A problem is reported with where it is; exit 1.")
    check.add_argument("--world", required=True, help=f"built-in name ({worlds}) or YAML path")
    check.add_argument("--json", action="store_true", help="print the summary as JSON")
    check.set_defaults(func=run_check)


def _builtin_world_names() -> list[str]:
    """The built-in world names, read from the package's files without importing pybullet."""
    spec = importlib.util.find_spec("sim")  # finds the package without running its __init__
    roots = spec.submodule_search_locations if spec else None
    return sorted(p.stem for root in roots or () for p in Path(root, "worlds").glob("*.yaml"))


def run_render(args: argparse.Namespace) -> int:
    from sim.render import render_world

    spec = _load(args.world)
    if spec is None:
        return _EXIT_BAD_INPUT
    out = Path(args.out) if args.out else Path(f"{spec.name}.png")
    if out.suffix.lower() != ".png":
        print(f"avs: error: --out {out}: expected a .png file", file=sys.stderr)
        return _EXIT_BAD_INPUT
    try:
        render_world(spec, out)
    except OSError as exc:
        print(f"avs: error: cannot write {out}: {exc.strerror or exc}", file=sys.stderr)
        return _EXIT_BAD_INPUT
    print(f"wrote {out}")
    return _EXIT_OK


def run_check(args: argparse.Namespace) -> int:
    spec = _load(args.world)
    if spec is None:
        return _EXIT_BAD_INPUT
    summary = _summary(spec)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{spec.source}: ok: world {spec.name!r} {spec.size[0]:g} x {spec.size[1]:g} m, "
              f"{len(spec.rooms)} rooms, {len(spec.doors)} doors, {len(spec.furniture)} "
              f"furniture, {len(spec.objects)} objects, robot {spec.robot.model}")
    return _EXIT_OK


def _load(world: str) -> WorldSpec | None:
    """Parse, validate, and build the world once (which also checks the robot's start and
    that every room category is one of the knowledge base's)."""
    from conceptual_map.knowledge import load_knowledge
    from sim.errors import SimError
    from sim.scene import World
    from sim.world_file import load_world_spec

    try:
        spec = load_world_spec(world)
        World(spec, categories=load_knowledge().categories).close()
    except SimError as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return None
    return spec


def _summary(spec: WorldSpec) -> dict[str, Any]:
    return {
        "name": spec.name,
        "source": spec.source,
        "size": list(spec.size),
        "rooms": {r.name: r.category for r in spec.rooms},
        "doors": [{"rooms": list(d.rooms), "open": d.open} for d in spec.doors],
        "furniture": {f.name: f.label for f in spec.furniture},
        "objects": {o.name: o.label for o in spec.objects},
        "robot": {"model": spec.robot.model, "start": list(spec.robot.start)},
    }
