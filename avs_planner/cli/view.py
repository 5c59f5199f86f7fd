"""`avs view RUN_DIR`: replay an episode's Rerun recording (the `viewer` extra)."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path
from typing import Any

from avs_planner.cli import EXIT_BAD_INPUT, EXIT_INTERNAL, EXIT_OK


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "view", help="replay an episode's recording in the Rerun viewer",
        description="Open RUN_DIR/recording.rrd (written by `avs simulate --record`) in the "
        "Rerun viewer: a window where a display is available, or a web viewer with --web. "
        "Needs `pip install 'avs-planner[viewer]'`.")
    parser.add_argument("run_dir", metavar="RUN_DIR",
                        help="an episode's output folder, or an .rrd file")
    how = parser.add_mutually_exclusive_group()
    how.add_argument("--web", action="store_true", help="serve the viewer to a browser "
                     "instead of opening a window (http://127.0.0.1:PORT; Ctrl-C stops it)")
    how.add_argument("--check", action="store_true", help="open nothing: read the recording "
                     "and print its entities and simulated-time range")
    parser.add_argument("--port", type=int, default=9090, help="--web: HTTP port (default 9090)")
    parser.set_defaults(func=run)


def _recording(run_dir: str) -> Path:
    from avs_planner.viewer import RECORDING

    path = Path(run_dir)
    if path.is_file() and path.suffix == ".rrd":
        return path
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such run folder")
    rrd = path / RECORDING
    if not rrd.is_file():
        raise FileNotFoundError(f"{path}: has no {RECORDING}; record an episode with "
                                f"`avs simulate ... --record --out {path}`")
    return rrd


def run(args: argparse.Namespace) -> int:
    from avs_planner.viewer import ViewerError, require_rerun
    from avs_planner.viewer.errors import display_missing

    try:
        rrd = _recording(args.run_dir)
        require_rerun("`avs view`")
    except (FileNotFoundError, ViewerError) as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.check:
        from avs_planner.viewer.replay import describe

        try:
            print(describe(rrd))
        except ViewerError as exc:
            print(f"avs: error: {exc}", file=sys.stderr)
            return EXIT_BAD_INPUT
        return EXIT_OK
    command = [sys.executable, "-m", "rerun"]
    if args.web:
        command += ["--web-viewer", "--web-viewer-port", str(args.port), "--bind", "127.0.0.1"]
        print(f"avs: serving {rrd} to a browser at http://127.0.0.1:{args.port} (Ctrl-C stops)",
              file=sys.stderr)
    elif display_missing():
        print(f"avs: error: cannot open the Rerun viewer's window: {display_missing()}. "
              f"Serve it to a browser with `avs view "
              f"{args.run_dir} --web`, or copy {rrd} to a machine with a display and run "
              f"`rerun {rrd.name}` there; `avs view {args.run_dir} --check` reads it here.",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        code = subprocess.call([*command, str(rrd)])
    except KeyboardInterrupt:
        return EXIT_OK
    except OSError as exc:
        print(f"avs: error: cannot start the Rerun viewer: {exc}", file=sys.stderr)
        return EXIT_INTERNAL
    if code != 0:
        print(f"avs: error: the Rerun viewer exited with status {code}", file=sys.stderr)
        return EXIT_INTERNAL
    return EXIT_OK
