"""Where the IPC benchmark set lives, and which of its domains the CP cannot take yet.

The set sits beside the project checkout (`../shared/ipc`); `AVS_IPC_DIR` points elsewhere.
Under CI (`CI` set) a missing set is an error, never a silent skip.

A domain folder holds `instance-N.pddl` files and either one `domain.pddl` for all of them
or one `domain-N.pddl` per instance (airport, openstacks, trucks): `domain_for` picks it.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IPC = Path(os.environ.get("AVS_IPC_DIR", ROOT.parent / "shared" / "ipc"))

# Domains the planner does not read yet (lenient reading took the last five: floortile,
# freecell, hiking, miconic, storage)
NOT_READ_YET: dict[str, str] = {}
# Domains it reads but does not solve within the test's limits (the anytime mode and
# conditional effects took barman and tetris off this list, the greedy phase's goal-count
# list and its search without commutation pruning took maintenance)
NOT_SOLVED_YET: dict[str, str] = {}

_INSTANCE = re.compile(r"instance-(\d+)\.pddl")


def require_ipc() -> Path:
    """The IPC folder; skips the test when it is absent, fails under CI."""
    import pytest  # here, so the benches can use the folder helpers without pytest

    if not IPC.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"IPC benchmark set missing at {IPC} (CI needs ../shared/ipc)")
        pytest.skip(f"IPC benchmark set not found at {IPC}")
    return IPC


def _number(instance: Path) -> int:
    match = _INSTANCE.fullmatch(instance.name)
    if match is None:
        raise ValueError(f"{instance} is not an IPC instance file (instance-N.pddl)")
    return int(match.group(1))


def ipc_folders(ipc: Path = IPC) -> list[Path]:
    """Every domain folder of the set, by name: those with a `domain.pddl` or a
    `domain-N.pddl` per instance. None when the set is absent."""
    if not ipc.is_dir():
        return []
    return sorted(f for f in ipc.iterdir() if f.is_dir() and (
        (f / "domain.pddl").is_file() or any(f.glob("domain-[0-9]*.pddl"))))


def instances(folder: Path) -> list[Path]:
    """A domain folder's `instance-N.pddl` files, by N (instance-2 before instance-10)."""
    return sorted((p for p in folder.glob("instance-*.pddl") if _INSTANCE.fullmatch(p.name)),
                  key=_number)


def domain_for(instance: Path) -> Path:
    """The domain file of an instance: its folder's `domain.pddl`, else the `domain-N.pddl`
    of `instance-N.pddl`."""
    shared = instance.parent / "domain.pddl"
    if shared.is_file():
        return shared
    own = instance.parent / f"domain-{_number(instance)}.pddl"
    if own.is_file():
        return own
    raise FileNotFoundError(f"no domain file for {instance}: neither {shared.name} nor "
                            f"{own.name} in {instance.parent}")


def ipc_domains(readable: bool = True, solvable: bool = False) -> list[str]:
    """Names of the IPC domains present, without the ones not read (or solved) yet."""
    names = [f.name for f in ipc_folders()]
    skip = (set(NOT_READ_YET) if readable else set()) | (set(NOT_SOLVED_YET) if solvable
                                                         else set())
    return [n for n in names if n not in skip]
