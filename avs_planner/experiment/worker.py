"""What runs in a worker process: one episode, its error caught and recorded, timed inside.

Kept light at module level; the episode runner (`avs_planner.harness:run_episode` unless a
test injects another `module:function` or `file.py:function`) is imported on first use or
preloaded by the backend.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

DEFAULT_RUNNER = "avs_planner.harness:run_episode"
PRELOAD = ("avs_planner.harness", "avs_planner.harness.runner")


def execute(spec: Mapping[str, Any], out_dir: str | None, runner: str = DEFAULT_RUNNER
            ) -> dict[str, Any]:
    """Run one episode into `out_dir`; a record with status ok or error and its timing."""
    start = time.perf_counter()
    try:
        function = resolve(runner)  # imported already in a warm worker; else not episode time
        start = time.perf_counter()
        summary = function({**spec, "output_dir": out_dir}, None, None)
    except Exception as exc:  # noqa: BLE001 - recorded with the run, never fatal
        return {"status": "error", "error": _describe(exc), "summary": None,
                "episode_s": time.perf_counter() - start}
    return {"status": "ok", "error": None, "summary": summary,
            "episode_s": time.perf_counter() - start}


def _describe(exc: Exception) -> str:
    where = traceback.extract_tb(exc.__traceback__)[-1:]
    place = f" (at {Path(where[0].filename).name}:{where[0].lineno})" if where else ""
    return f"{type(exc).__name__}: {exc}{place}"


def resolve(spec: str) -> Callable[..., Any]:
    """A function from 'package.module:name' or '/path/to/file.py:name'."""
    target, sep, name = spec.rpartition(":")
    if not sep or not target or not name:
        raise ValueError(f"runner {spec!r} is not 'module:function' or 'file.py:function'")
    if target.endswith(".py"):
        module_name = f"_avs_campaign_runner_{Path(target).stem}"
        module = sys.modules.get(module_name)
        if module is None:
            found = importlib.util.spec_from_file_location(module_name, target)
            if found is None or found.loader is None:
                raise ValueError(f"cannot load runner file {target}")
            module = importlib.util.module_from_spec(found)
            sys.modules[module_name] = module
            found.loader.exec_module(module)
    else:
        module = importlib.import_module(target)
    return getattr(module, name)


def preload(runner: str = DEFAULT_RUNNER) -> None:
    """Import the episode stack now, so an episode's clock does not pay for it."""
    for name in PRELOAD:
        importlib.import_module(name)
    resolve(runner)


def execute_collect(spec: Mapping[str, Any], runner: str = DEFAULT_RUNNER) -> dict[str, Any]:
    """`execute` into a temporary directory, with the files it wrote in the record (`files`:
    name -> bytes), for a worker on another machine than the one that keeps the results."""
    with tempfile.TemporaryDirectory(prefix="avs-run-") as tmp:
        record = execute(spec, tmp, runner)
        record["files"] = {p.name: p.read_bytes() for p in Path(tmp).iterdir() if p.is_file()}
    return record
