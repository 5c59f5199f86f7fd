"""`avs plan --json | head`: a reader that goes away early is not an internal error; the
command exits with its broken-pipe status and prints no traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from avs_planner.cli import EXIT_BROKEN_PIPE

ROOT = Path(__file__).resolve().parents[3]


def test_closed_stdout_exits_quietly() -> None:
    command = [sys.executable, "-c", "import sys; from avs_planner.cli import main; "
               "sys.exit(main(sys.argv[1:]))", "plan", "--json",
               str(ROOT / "domains/avs/domain.pddl"),
               str(ROOT / "domains/avs/problems/corridor.pddl")]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               cwd=ROOT)
    assert process.stdout is not None and process.stderr is not None
    process.stdout.close()  # like `| head -c 0`: nobody reads
    error = process.stderr.read().decode()
    assert process.wait(timeout=120) == EXIT_BROKEN_PIPE
    assert "internal error" not in error and "Traceback" not in error
