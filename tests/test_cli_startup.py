"""`avs` starts fast: building the parser must not import the heavy libraries.

Subcommand modules are discovered and imported to build the parser, so each keeps pybullet,
unified-planning, matplotlib and FastAPI imports inside the function that runs the command.
`avs plan` and `avs domain check` read and ground PDDL on the project's own model
(`pddl.lite`): they do not import unified-planning at all (it alone took ~0.8 s); nor does a
search episode (`avs simulate`), which builds each replan's problem in that model.

An episode starts (its trace's `start` event) without the libraries it does not need then:
pomdp-py (the DT, loaded by the first view-cone search), pgmpy (only to export the chain
graph's factors), scipy.stats, FLAP (the `views: flap` option). Checked by the modules loaded
when the event is emitted, not by a time (`--scenario a --seed 1`, CPU seconds from launch to
the event, median of 7: 1.81 with them, 0.83 without).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CORRIDOR = ["domains/avs/domain.pddl", "domains/avs/problems/corridor.pddl"]

HEAVY = ("pybullet", "unified_planning", "matplotlib", "fastapi", "pgmpy", "pomdp_py")


def test_building_the_parser_imports_no_heavy_library() -> None:
    code = (
        "import sys; from avs_planner.cli import build_parser; build_parser(); "
        f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"imported at start-up: {out.stdout.strip()}"


def test_help_lists_the_commands() -> None:
    out = subprocess.run([sys.executable, "-m", "avs_planner", "--help"], capture_output=True,
                         text=True, check=True)
    for command in ("plan", "domain", "sim", "serve"):
        assert command in out.stdout


@pytest.mark.parametrize("argv", [["plan", *CORRIDOR], ["plan", "--json", *CORRIDOR],
                                  ["domain", "check", *CORRIDOR]], ids=" ".join)
def test_plan_and_domain_check_do_not_import_unified_planning(argv: list[str]) -> None:
    code = (f"import sys; from avs_planner.cli import main; rc = main({argv!r}); "
            "print('UP' if 'unified_planning' in sys.modules else 'no UP', rc)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    assert out.stdout.strip().splitlines()[-1] == "no UP 0", out.stderr


# not imported before an episode's first event (see the module's doc)
NOT_BEFORE_START = ("pomdp_py", "pgmpy", "scipy.stats", "sklearn", "pandas", "avs_planner.flap",
                    "unified_planning", "fastapi")


def test_a_search_episode_starts_without_the_libraries_it_does_not_need_then(
        tmp_path: Path) -> None:
    """The modules loaded when `avs simulate` emits the episode's `start` event (the process
    ends there: the episode's own steps are not run)."""
    argv = ["simulate", "--scenario", "a", "--seed", "1", "--out", str(tmp_path / "episode")]
    code = (
        "import os, sys\n"
        "from avs_planner.episode import trace\n"
        "emit = trace.Trace.emit\n"
        "def at_start(self, type_, **fields):\n"
        "    if type_ == 'start':\n"
        f"        loaded = [m for m in {NOT_BEFORE_START!r} if m in sys.modules]\n"
        "        print('loaded at start:', *loaded, flush=True)\n"
        "        os._exit(0)\n"
        "    return emit(self, type_, **fields)\n"
        "trace.Trace.emit = at_start\n"
        "from avs_planner.cli import main\n"
        f"main({argv!r})\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    assert out.stdout.strip().splitlines()[-1] == "loaded at start:", out.stdout + out.stderr


def test_a_search_episode_does_not_import_unified_planning(tmp_path: Path) -> None:
    """The episode builds and plans each replan's problem on `pddl.lite` (episode/domain.py)."""
    argv = ["simulate", "--scenario", "a", "--seed", "1", "--time-budget", "30",
            "--out", str(tmp_path / "episode")]
    code = (f"import sys; from avs_planner.cli import main; rc = main({argv!r}); "
            "print('UP' if 'unified_planning' in sys.modules else 'no UP', rc, "
            "'pgmpy' in sys.modules, 'pomdp_py' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    last = out.stdout.strip().splitlines()[-1].split()
    assert last[:2] == ["no", "UP"], out.stdout + out.stderr
    assert (tmp_path / "episode" / "trace.jsonl").exists()
    # pgmpy never (the chain graph needs numpy only); pomdp-py with the first DT session
    summary = json.loads((tmp_path / "episode" / "summary.json").read_text())
    assert last[3:] == ["False", str(summary["dt_calls"] > 0)], out.stdout
