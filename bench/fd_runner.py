"""Fast Downward run as its own driver, with its own clocks read from its log.

`OneshotPlanner(name="fast-downward")` starts a new Python interpreter and writes PDDL before
FD does any work (~0.1 s on this machine), so its wall time flatters anything it is compared
with. Here the driver (`fast-downward.py --alias lama-first`, from up-fast-downward) runs on
PDDL files and two times are kept: FD's own (the translator's "Done! [... wall-clock]",
measured inside it after its imports, plus the search component's "Total time") and the
end-to-end wall time of the driver. A run past the limit is killed with its process group.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

_TRANSLATE = re.compile(r"^Done! \[[\d.]+s CPU, ([\d.]+)s wall-clock\]", re.MULTILINE)
_SEARCH = re.compile(r"\] Total time: ([\d.]+)s", re.MULTILINE)
_SOLVED = "Solution found."


@dataclass(frozen=True)
class FdRun:
    """One FD run: `own_s` = translate + search as FD measures them; `wall_s` = the driver
    end to end; both the limit when it failed or timed out."""

    solved: bool
    own_s: float
    wall_s: float
    translate_s: float = 0.0
    search_s: float = 0.0
    plan: tuple[tuple[str, tuple[str, ...]], ...] = ()
    timed_out: bool = False


def driver() -> Path | None:
    """fast-downward.py of the installed up-fast-downward, or None."""
    try:
        import up_fast_downward
    except ImportError:
        return None
    path = Path(up_fast_downward.__file__).parent / "downward" / "fast-downward.py"
    return path if path.exists() else None


def run_fd(domain: Path, problem: Path, limit_s: float, alias: str = "lama-first") -> FdRun:
    """Run FD on two PDDL files in a scratch folder; never raises for FD's failures."""
    script = driver()
    if script is None:
        raise SystemExit("up-fast-downward is not installed (pip install 'up-fast-downward>=0.4',"
                         " the project's bench extra)")
    with tempfile.TemporaryDirectory(prefix="fd-") as work:
        command = [sys.executable, str(script), "--alias", alias, str(domain), str(problem)]
        start = time.perf_counter()
        proc = subprocess.Popen(command, cwd=work, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, start_new_session=True)
        try:
            log, _ = proc.communicate(timeout=limit_s)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
            return FdRun(False, limit_s, limit_s, timed_out=True)
        wall = time.perf_counter() - start
        plan_file = Path(work) / "sas_plan"
        steps = _read_plan(plan_file) if plan_file.exists() else None
    return _result(log, wall, steps, limit_s)


def _result(log: str, wall: float, steps, limit_s: float) -> FdRun:
    translate = _TRANSLATE.search(log)
    search = _SEARCH.search(log)
    if _SOLVED not in log or steps is None or translate is None or search is None:
        return FdRun(False, limit_s, limit_s)
    t, s = float(translate.group(1)), float(search.group(1))
    return FdRun(True, t + s, wall, t, s, steps)


def _read_plan(path: Path) -> tuple[tuple[str, tuple[str, ...]], ...]:
    steps = []
    for line in path.read_text().splitlines():
        line = line.strip()
        if line.startswith("(") and line.endswith(")"):
            name, *args = line[1:-1].split()
            steps.append((name, tuple(args)))
    return tuple(steps)
