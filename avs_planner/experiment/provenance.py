"""Which code produced a campaign's numbers: the git commit and whether the tree was dirty.

`avs experiment run` records this once per invocation (in campaign.json) and in every run's
record (the `commit` column of results.csv), and the report stamps every table with it. Outside
a git checkout (an installed wheel, no git on the PATH) the commit is "unknown".
"""

from __future__ import annotations

import subprocess
from pathlib import Path
from typing import Any

UNKNOWN = "unknown"
SOURCE_ROOT = Path(__file__).resolve().parents[2]  # the checkout holding avs_planner/


def git_state(root: Path = SOURCE_ROOT, timeout_s: float = 20.0) -> dict[str, Any]:
    """`{"commit": short hash or "unknown", "dirty": True/False, or None when unknown}`.

    Dirty means a tracked file differs from the commit (staged or not); untracked files
    (say, a campaign's output directory inside the checkout) do not count."""
    commit = _git(root, timeout_s, "rev-parse", "--short", "HEAD")
    if not commit:
        return {"commit": UNKNOWN, "dirty": None}
    status = _git(root, timeout_s, "status", "--porcelain", "--untracked-files=no")
    return {"commit": commit, "dirty": None if status is None else bool(status)}


def describe(state: dict[str, Any] | None) -> str:
    """`abc1234`, `abc1234+dirty` or `unknown`, as results.csv's `commit` column has it."""
    if not state or not state.get("commit") or state["commit"] == UNKNOWN:
        return UNKNOWN
    return str(state["commit"]) + ("+dirty" if state.get("dirty") else "")


def _git(root: Path, timeout_s: float, *args: str) -> str | None:
    try:
        done = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True,
                              timeout=timeout_s, check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None
