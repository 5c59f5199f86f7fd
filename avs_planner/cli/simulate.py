"""`avs simulate`: one headless object-search episode (the switching planner in the loop).

Writes trace.jsonl, summary.json and trajectory.png to --out, prints a progress line while it
runs and a short summary at the end. Exit codes: 0 found, 2 gave up, 3 timeout, 1 bad input.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Any

EXIT_FOUND, EXIT_BAD_INPUT, EXIT_GAVE_UP, EXIT_TIMEOUT = 0, 1, 2, 3
_EXIT = {"found": EXIT_FOUND, "gave_up": EXIT_GAVE_UP, "timeout": EXIT_TIMEOUT}


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "simulate", help="run one object-search episode in a simulated world",
        description="Run the switching planner in the loop on a simulated robot until the "
                    "object is found, the search is hopeless, or the time budget is spent. "
                    "Exit codes: 0 found, 1 bad input, 2 gave up, 3 timeout.")
    parser.add_argument("--world", help="built-in world name or world YAML path (default: "
                        "office, or the scenario's)")
    parser.add_argument("--generated", type=int, metavar="SEED",
                        help="a generated world (see `avs world generate`) instead of --world")
    parser.add_argument("--style", help="generated world style "
                        "(office, apartment, lab; default office)")
    parser.add_argument("--rooms", type=int, help="generated world: number of rooms")
    parser.add_argument("--target", action="append", default=None, metavar="LABEL",
                        help="object label to find, e.g. cerealbox; a label the "
                        "knowledge does not list is searched for with its uninformed prior "
                        "(see domains/README.md), with a warning in the trace. Repeat it for "
                        "a task of several objects (docs/tasks.md)")
    parser.add_argument("--mode", choices=["all", "any"], help="with several --target: find "
                        "one of each (all, the default) or stop at the first of any")
    parser.add_argument("--count", choices=["one", "all"], help="all: find every instance of "
                        "the one --target, until P(another one unseen) < --stop-below")
    parser.add_argument("--stop-below", type=float, metavar="P", help="with --count all: the "
                        "probability of another one unseen at which the search stops "
                        "(default 0.1)")
    parser.add_argument("--strict-labels", action="store_true", help="refuse a target label "
                        "the knowledge does not list (exit 1) instead of searching for it with "
                        "the uninformed prior")
    parser.add_argument("--scenario", help="one of the active visual search paper's runs "
                        "a-f (Fig. 3), or a scenario YAML path; other options override it")
    parser.add_argument("--category", help="only an object in a room of this category")
    parser.add_argument("--robot", choices=["pioneer", "pr2"])
    parser.add_argument("--strategy", default=None, help="search strategy: switching (the "
                        "default), exhaustive, most-likely-room, ... (an unknown name lists "
                        "them all)")
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="a strategy option, e.g. --option reward=800 (repeatable)")
    parser.add_argument("--qsr", metavar="FILE",
                        help="QSR descriptions for the qsr strategy: a YAML list (or a mapping "
                             "with a 'descriptions' list) in the format of "
                             "conceptual_map/qsr/README.md; default: the built-in knowledge")
    parser.add_argument("--experience", metavar="PATH", help="an experience store (SQLite; "
                        "made when missing): the episode searches with the priors it learned "
                        "and adds what it saw when it ends (docs/learning.md; see "
                        "`avs knowledge show`)")
    parser.add_argument("--building", metavar="ID", help="with --experience: the building's "
                        "id, whose own counts refine the all-buildings ones")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--start-room", help="start at the centre of this room")
    where.add_argument("--start", help="start pose x,y,yaw (metres, radians)")
    parser.add_argument("--seed", type=int, help="sensor noise seed (default 0)")
    parser.add_argument("--time-budget", type=float, help="simulated seconds (default 1200)")
    parser.add_argument("--pre-explore", action="store_true", help="map the building before "
                        "the clock starts (the strategy's own survey where it has one, e.g. "
                        "flap's with depth frames)")
    parser.add_argument("--memory", metavar="DIR", help="the building's memory: start from "
                        "what the robot learned in DIR in earlier tasks (map, furniture, "
                        "sightings to check again) and keep this task's there; created when "
                        "missing (docs/memory.md)")
    parser.add_argument("--since", type=float, metavar="S", help="with --memory: simulated "
                        "seconds since the building's last task (default 3600); sightings "
                        "fade with it")
    parser.add_argument("--out", default=None,
                        help="output directory (default: a new one under runs/ named after "
                        "the world and target, e.g. runs/office-cerealbox-2: a run never "
                        "overwrites an earlier one unless --out names it)")
    parser.add_argument("--record", action="store_true", help="also write OUT/recording.rrd, "
                        "a Rerun recording (needs `pip install 'avs-planner[viewer]'`; replay "
                        "it with `avs view OUT`)")
    parser.add_argument("--view", action="store_true", help="stream the episode live to a "
                        "Rerun viewer spawned for it (needs the viewer extra and a display)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from avs_planner.episode import EpisodeError
    from avs_planner.harness import EpisodeSpec, run_episode
    from avs_planner.harness.scenarios import load_scenario

    try:
        base: dict[str, Any] = {}
        if args.scenario:
            base = load_scenario(args.scenario).spec
        spec = _spec(args, base)
        checked = EpisodeSpec.from_dict(spec)  # bad options or QSR descriptions: exit 1
        _check_label(checked)  # before the run, as a label refused with --strict-labels
        _check_start(checked)  # a pose outside the building is refused, as the API does
        _check_out(Path(args.out))
        if checked.memory is not None:
            from avs_planner.episode import memory

            memory.load(checked.memory)  # a memory that cannot be read: exit 1, named
        _check_experience(checked)
    except (EpisodeError, ValueError) as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    tty = sys.stderr.isatty()
    progress = _Progress(enabled=tty or not args.json, tty=tty)
    summary = run_episode(spec, progress, None)
    progress.finish()
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        _print_summary(summary, Path(args.out))
    return _EXIT.get(summary["outcome"], EXIT_TIMEOUT)


def _check_experience(spec: Any) -> None:
    """An --experience file that exists must be an experience store (before the run)."""
    if spec.experience is None or not Path(spec.experience).exists():
        return
    from conceptual_map.errors import ExperienceError
    from conceptual_map.knowledge.experience import ExperienceStore

    try:
        ExperienceStore(spec.experience, create=False).close()
    except ExperienceError as exc:
        raise ValueError(f"--experience: {exc}") from None


def _check_label(spec: Any) -> None:
    """With `--strict-labels`, a target the knowledge does not list is bad input."""
    if spec.strict_labels:
        from avs_planner.harness.runner import target_knowledge
        from conceptual_map.knowledge import load_knowledge

        knowledge = load_knowledge()
        for label in spec.form.targets:
            target_knowledge(knowledge, label, strict=True)


def _check_start(spec: Any) -> None:
    """`--start` must stand on a free spot of a room of the world (else the robot would
    search from outside the building until its budget ran out)."""
    if spec.start is None or spec.world_text is not None:
        return  # an inline world file is checked by the runner
    from avs_planner.harness.sim_robot import generated_spec, load_spec
    from avs_planner.harness.validate import start_problem

    world = generated_spec(spec.generate) if spec.generate else load_spec(spec.world)
    problem = start_problem(world, spec.start, spec.robot or world.robot.model)
    if problem:
        raise ValueError(f"--start: {problem}")


def _check_out(out: Path) -> None:
    """The output directory can be made and written to (a clear error, not a traceback
    after the episode has run)."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".avs-write-test"
        probe.write_text("", encoding="utf-8")
        probe.unlink()
    except OSError as exc:
        raise ValueError(f"--out {str(out)!r} cannot be written: {exc.strerror or exc}") \
            from None


def _check_flags(args: argparse.Namespace) -> None:
    """Flags that would be silently ignored together are an error."""
    if args.generated is not None and args.world:
        raise ValueError("--generated SEED and --world name two different worlds: give one")
    if args.building is not None and args.experience is None:
        raise ValueError("--building names a scope of the experience store: use it with "
                         "--experience PATH")
    if args.generated is None and (args.style is not None or args.rooms is not None):
        raise ValueError("--style and --rooms shape a generated world: use them with "
                         "--generated SEED")


def _spec(args: argparse.Namespace, base: dict[str, Any]) -> dict[str, Any]:
    _check_flags(args)
    spec = dict(base)
    _task(args, spec)
    for key, value in (("world", args.world), ("category", args.category), ("robot", args.robot),
                       ("seed", args.seed), ("time_budget_s", args.time_budget)):
        if value is not None:
            spec[key] = value
    if args.start_room:
        spec.pop("start", None)
        spec["start_room"] = args.start_room
    if args.start:
        spec.pop("start_room", None)
        spec["start"] = _pose(args.start)
    if args.generated is not None:
        spec.pop("world", None)
        spec["generate"] = {"seed": args.generated, "style": args.style or "office",
                            "rooms": args.rooms}
    if args.strategy:
        spec["strategy"] = args.strategy
    if args.pre_explore:
        spec["pre_explore"] = True
    if args.strict_labels:
        spec["strict_labels"] = True
    if args.option:
        spec["strategy_options"] = dict(_option(text) for text in args.option)
    if args.qsr:
        spec["qsr"] = _qsr_file(args.qsr)
    if args.since is not None and args.memory is None:
        raise ValueError("--since S is the time since the building's last task: use it with "
                         "--memory DIR")
    if args.memory is not None:
        spec["memory"] = args.memory
    if args.since is not None:
        spec["since_s"] = args.since
    if args.experience is not None:
        spec["experience"] = args.experience
    if args.building is not None:
        spec["building"] = args.building
    if args.record:
        spec["record"] = True
    if args.view:
        spec["view"] = True
    if not spec.get("target") and not spec.get("targets"):
        raise ValueError("--target LABEL (or --scenario) is required")
    if args.out is None:
        args.out = str(_fresh_out(spec))
    spec["output_dir"] = args.out
    return spec


def _task(args: argparse.Namespace, spec: dict[str, Any]) -> None:
    """--target (once, or repeated for a task of several), --mode, --count, --stop-below into
    the spec (a scenario's own target is replaced by the flags')."""
    labels = args.target or []
    if len(labels) > 1:
        spec.pop("target", None)
        spec["targets"] = labels
    elif labels:
        spec.pop("targets", None)
        spec["target"] = labels[0]
    for key, value in (("mode", args.mode), ("count", args.count),
                       ("stop_below", args.stop_below)):
        if value is not None:
            spec[key] = value
    if args.mode is not None and len(labels) < 2 and not spec.get("targets"):
        raise ValueError("--mode combines several objects: repeat --target (e.g. --target "
                         "cup --target book --mode any)")


def _fresh_out(spec: dict[str, Any], root: Path = Path("runs")) -> Path:
    """runs/WORLD-TARGET, or the first of -2, -3, ... not taken by an earlier run."""
    gen = spec.get("generate")
    if gen:
        world = f"gen-{gen.get('style', 'office')}-{gen.get('seed')}"
    else:
        world = Path(str(spec.get("world") or "office")).stem
    what = spec.get("target") or "+".join(spec.get("targets") or ())
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", f"{world}-{what}")
    out, n = root / stem, 1
    while out.exists():
        n += 1
        out = root / f"{stem}-{n}"
    return out


def _qsr_file(path: str) -> Any:
    """The descriptions of a --qsr file (validated with the episode spec)."""
    import yaml

    try:
        data = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise ValueError(f"--qsr {path}: cannot read: {exc.strerror}") from None
    except yaml.YAMLError as exc:
        raise ValueError(f"--qsr {path}: YAML error: {exc}") from None
    if isinstance(data, dict) and "descriptions" in data:
        data = data["descriptions"]
    return data


def _option(text: str) -> tuple[str, str]:
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise ValueError(f"--option {text!r}: expected KEY=VALUE, e.g. reward=800")
    return key.strip(), value.strip()


def _pose(text: str) -> list[float]:
    parts = text.split(",")
    try:
        pose = [float(p) for p in parts]
    except ValueError:
        pose = []
    if len(pose) != 3:
        raise ValueError(f"--start {text!r}: expected x,y,yaw, e.g. 6.0,3.2,0")
    return pose


class _Progress:
    """The episode's progress on stderr: sim time, plans, the step being executed. On a
    terminal one status line rewritten in place; elsewhere (a log, a pipe) one line per
    finished step, so a log reads as lines and not as carriage returns."""

    def __init__(self, enabled: bool, tty: bool = True):
        self.enabled, self.tty = enabled, tty
        self.plans = 0
        self.shown = False

    def __call__(self, event: dict[str, Any]) -> None:
        if event["type"] == "plan":
            self.plans += 1
        if not self.enabled or event["type"] not in ("plan", "action", "dt", "done"):
            return
        if not self.tty and (event["type"] == "plan" or event.get("status") == "start"):
            return
        what = event.get("action") or event.get("result") or event.get("outcome") or ""
        if event["type"] == "action" and event.get("status") not in (None, "start", "done"):
            what = f"{what} {event['status']}"
        line = f"t={event['t']:7.1f}s  plans={self.plans:3d}  {event['type']:6s} {what}"
        if self.tty:
            print("\r" + line[:100].ljust(100), end="", file=sys.stderr, flush=True)
        else:
            print(line, file=sys.stderr, flush=True)
        self.shown = True

    def finish(self) -> None:
        if self.shown and self.tty:
            print(file=sys.stderr)


def _print_summary(summary: dict[str, Any], out: Path) -> None:
    obj = summary.get("object") or {}
    found = (f"found {obj.get('label')} at ({obj['position'][0]:.2f}, {obj['position'][1]:.2f})"
             f" in {obj.get('room')}" if obj else summary["outcome"].replace("_", " "))
    cp = summary["cp_time_s"]
    if summary.get("targets"):
        found = summary["outcome"].replace("_", " ")
    print(f"{summary['target']}: {found} ({summary['reason']})")
    for part in summary.get("targets") or ():
        where = "; ".join(f"{o['label']} at ({o['position'][0]:.2f}, {o['position'][1]:.2f}) "
                          f"in {o['room']}" for o in part["objects"])
        when = "" if part["sim_time_s"] is None else f" at {part['sim_time_s']:.1f} s"
        if part["outcome"] == "not_needed":
            print(f"  {part['label']}: {part['reason']}")
            continue
        print(f"  {part['label']}: {part['outcome'].replace('_', ' ')}{when}"
              + (f": {where}" if where else f" ({part['reason']})"))
    print(f"  simulated {summary['sim_time_s']:.1f} s, drove {summary['distance_m']:.1f} m, "
          f"{summary['plans']} plans (CP {sum(cp):.2f} s), {summary['dt_calls']} DT searches "
          f"({summary.get('dt_confirmed', 0)} confirmed, {summary.get('dt_rejected', 0)} "
          f"rejected), "
          f"{summary['views_processed']} views, wall {summary['wall_time_s']:.1f} s")
    mem = summary.get("memory")
    if mem:
        start = (f"after {mem['tasks_before']} earlier task(s): {mem['furniture']} furniture, "
                 f"{mem['sightings']} sighting(s), {mem['checked']} checked, "
                 f"{mem['confirmed']} seen again" if mem["tasks_before"] else "nothing yet")
        print(f"  memory: {start}; kept this task's")
    files = [out / name for name in ("trace.jsonl", "summary.json", "explanation.json",
                                      "trajectory.png", "recording.rrd")
             if (out / name).exists()]
    print(f"  wrote {', '.join(str(f) for f in files)}")
    print(f"  why: avs explain {out}" + (f"; replay: avs view {out}"
                                          if (out / "recording.rrd").exists() else ""))
