"""`avs` starts fast: building the parser must not import the heavy libraries.

Subcommand modules are discovered and imported to build the parser, so each keeps pybullet,
unified-planning, matplotlib and FastAPI imports inside the function that runs the command.
"""

from __future__ import annotations

import subprocess
import sys

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
