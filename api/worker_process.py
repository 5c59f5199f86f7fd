"""What runs inside a worker process: a loop taking jobs over a pipe and sending back events.

Kept free of heavy imports at module level so a spawned worker starts fast; the job functions
(`avs_planner.jobs` or an injected episode runner) are imported on first use.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import resource
import sys
import threading
import time
import traceback
from collections.abc import Callable
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

STOP = "stop"
PRELOAD_JOBS = ("avs_planner.jobs", "avs_planner.pddl", "avs_planner.cp.planner")
JOB_FUNCTIONS = {
    "plan": "avs_planner.jobs:plan",
    "check": "avs_planner.jobs:check_domain",
}


def resolve(spec: str) -> Callable[..., Any]:
    """A function from 'package.module:name' or '/path/to/file.py:name'."""
    target, sep, name = spec.rpartition(":")
    if not sep or not target or not name:
        raise ValueError(f"runner spec {spec!r} is not 'module:function' or 'file.py:function'")
    if target.endswith(".py"):
        path = Path(target)
        module_spec = importlib.util.spec_from_file_location(f"_avs_runner_{path.stem}", path)
        if module_spec is None or module_spec.loader is None:
            raise ValueError(f"cannot load runner file {target}")
        module = importlib.util.module_from_spec(module_spec)
        sys.modules[module_spec.name] = module  # dataclasses and pickling look it up there
        module_spec.loader.exec_module(module)
    else:
        module = importlib.import_module(target)
    return getattr(module, name)


def limit_memory(memory_limit_mb: int) -> None:
    """Cap this process's address space so a runaway job fails with MemoryError, not the host."""
    if memory_limit_mb <= 0:
        return
    limit = memory_limit_mb * 1024 * 1024
    _soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


class _Channel:
    """The worker's end of the pipe: emit events, notice a stop request."""

    def __init__(self, conn: Connection):
        self.conn = conn
        self.stopped = False

    def emit(self, event: dict[str, Any]) -> None:
        self.conn.send(("event", dict(event)))

    def should_stop(self) -> bool:
        while not self.stopped and self.conn.poll():
            self.stopped = self.conn.recv() == STOP
        return self.stopped


def _run_job(channel: _Channel, runners: dict[str, str], kind: str, payload: dict[str, Any]
             ) -> Any:
    if kind == "episode":
        runner = resolve(runners["episode"])
        return runner(payload, channel.emit, channel.should_stop)
    function = resolve(runners.get(kind) or JOB_FUNCTIONS[kind])
    return function(**payload)


def preload(modules: tuple[str, ...]) -> None:
    """Import what the jobs will need before the first job arrives (best effort)."""
    for name in modules:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 - the job itself reports a missing module properly
            pass


def exit_with_parent(interval_s: float = 1.0) -> None:
    """Exit when the service process dies (even by SIGKILL), so no episode runs orphaned."""
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(interval_s)
        os._exit(1)

    threading.Thread(target=watch, name="avs-parent-watch", daemon=True).start()


def worker_main(
    conn: Connection, memory_limit_mb: int, runners: dict[str, str],
    modules: tuple[str, ...] = (), nice: int = 0,
) -> None:
    """Serve jobs until the pipe closes or a None job arrives."""
    exit_with_parent()
    if nice:
        os.nice(nice)  # batch work yields the CPU to the service's request handling
    limit_memory(memory_limit_mb)
    preload(modules)
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        if message == STOP:  # a stop that arrived after its job ended
            continue
        kind, payload = message
        channel = _Channel(conn)
        try:
            value = _run_job(channel, runners, kind, payload)
            conn.send(("result", value))
        except MemoryError:
            conn.send(("error", "MemoryError", f"memory limit of {memory_limit_mb} MB exceeded"))
        except Exception as exc:  # noqa: BLE001 - reported to the parent, never lost
            name = type(exc).__name__
            detail = str(exc) or traceback.format_exc(limit=3)
            conn.send(("error", name, detail))
