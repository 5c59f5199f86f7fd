"""Where episodes run: the local backend, one fresh process per episode, and the job contract.

Each local episode runs in its own process, forked from a forkserver that has imported the
episode stack once, so a new process costs milliseconds, not the 2 s of imports, and no
state survives from one episode to the next. A slot thread per worker starts the process,
waits for its record or its deadline (then kills it), and hands the record back. The Ray
backend (`ray_backend.py`) keeps the same contract.

A job may carry the episodes that must follow it (`Job.then`: the later tasks of a campaign
sequence, which read the memory the earlier ones wrote): a backend runs them one after another,
each handed back on its own as it finishes, the next started only after the one before was
handed back; different jobs still run side by side.
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import os
import shutil
import sys
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import Any, Protocol

from avs_planner.experiment.campaign import RunSpec
from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.worker import DEFAULT_RUNNER, PRELOAD, execute

Record = dict[str, Any]


@dataclass(frozen=True)
class Job:
    """One episode to run: its spec, its directory and its hard wall-clock limit."""

    run: RunSpec
    out_dir: Path
    deadline_s: float
    then: tuple[Job, ...] = ()  # episodes to run after this one, in order, in the same slot
    # the campaign sequence's memory directory (memory on), and the snapshot of it to start
    # from (the one the episode before left; None: start with no memory)
    memory: Path | None = None
    memory_from: Path | None = None

    def steps(self) -> list[Job]:
        """This episode and those that follow it, in order (each without followers)."""
        return [dataclasses.replace(job, then=()) for job in (self, *self.then)]


MEMORY_SNAPSHOT = "memory"  # in a run's directory: its sequence's memory as the episode left it


def start_dir(job: Job) -> None:
    """A fresh run directory, and a sequence's memory as the episode before left it."""
    fresh_dir(job.out_dir)
    if job.memory is None:
        return
    if job.memory.exists():
        shutil.rmtree(job.memory)
    if job.memory_from is not None and job.memory_from.is_dir():
        shutil.copytree(job.memory_from, job.memory)
    else:
        job.memory.mkdir(parents=True)


def keep_memory(job: Job) -> None:
    """Keep what the episode left in its sequence's memory beside its record (the next
    episode starts from it, also when it runs again after a stop)."""
    if job.memory is None:
        return
    snapshot = job.out_dir / MEMORY_SNAPSHOT
    if snapshot.exists():
        shutil.rmtree(snapshot)
    if job.memory.is_dir():
        shutil.copytree(job.memory, snapshot)
    else:
        snapshot.mkdir(parents=True)


OnDone = Callable[[Job, Record], None]


class Backend(Protocol):
    slots: int
    name: str

    def run(self, jobs: Iterable[Job], on_done: OnDone) -> None: ...

    def close(self) -> None: ...


def make_backend(name: str, workers: int | None, address: str | None,
                 runner: str = DEFAULT_RUNNER) -> Backend:
    if workers is not None and workers < 1:
        raise CampaignError(f"--workers must be at least 1, got {workers}")
    if name == "local":
        if address is not None:
            raise CampaignError("--address is for the ray backend")
        return LocalBackend(workers or default_workers(), runner)
    if name == "ray":
        from avs_planner.experiment.ray_backend import RayBackend

        return RayBackend(workers, address, runner)
    raise CampaignError(f"unknown backend {name!r}; use local or ray")


def default_workers() -> int:
    """One worker per CPU this process may use."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
               else os.cpu_count() or 1)


def fresh_dir(path: Path) -> None:
    """An empty run directory (a stopped attempt may have left a partial trace)."""
    if path.exists():
        shutil.rmtree(path)
    path.mkdir(parents=True)


class LocalBackend:
    """`slots` episodes at a time on this machine, each in its own forked process."""

    name = "local"

    def __init__(self, slots: int, runner: str = DEFAULT_RUNNER):
        self.slots = slots
        self.runner = runner
        self._ctx = multiprocessing.get_context("forkserver")
        module = runner.rpartition(":")[0]
        extra = [] if module.endswith(".py") or module in PRELOAD else [module]
        self._ctx.set_forkserver_preload(["avs_planner.experiment.worker", *PRELOAD, *extra])
        self._live: set[multiprocessing.process.BaseProcess] = set()
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._failure: BaseException | None = None

    def run(self, jobs: Iterable[Job], on_done: OnDone) -> None:
        todo = list(jobs)
        if not todo:
            return
        queue = iter(todo)
        self._warm()
        threads = [threading.Thread(target=self._slot, args=(queue, on_done), daemon=True,
                                    name=f"avs-campaign-slot-{i}") for i in range(self.slots)]
        for thread in threads:
            thread.start()
        try:
            for thread in threads:
                while thread.is_alive():
                    thread.join(0.5)  # a short join keeps Ctrl-C deliverable
        finally:
            self._stopping.set()
            self._kill_all()
            for thread in threads:
                thread.join(10)
        if self._failure is not None:
            raise self._failure  # e.g. the disk filled up while writing a record

    def close(self) -> None:
        self._kill_all()

    def _warm(self) -> None:
        """Start the forkserver (it imports the episode stack) before any episode's clock."""
        process = self._ctx.Process(target=_noop, daemon=True)
        process.start()
        process.join()

    def _slot(self, queue: Iterable[Job], on_done: OnDone) -> None:
        try:
            self._serve(queue, on_done)
        except BaseException as exc:  # noqa: BLE001 - handed to the main thread by `run`
            self._failure = exc
            self._stopping.set()

    def _serve(self, queue: Iterable[Job], on_done: OnDone) -> None:
        for unit in _locked(queue, self._lock):
            for job in unit.steps():  # a sequence's episodes one after another
                if self._stopping.is_set():
                    return
                record = self._one(job)
                if self._stopping.is_set():
                    return  # interrupted: leave the run for the next attempt
                with self._lock:
                    on_done(job, record)

    def _one(self, job: Job) -> Record:
        start_dir(job)
        start = time.perf_counter()
        reader, writer = self._ctx.Pipe(duplex=False)
        process = self._ctx.Process(target=_child, daemon=True, name=f"avs-{job.run.run_id}",
                                    args=(writer, dict(job.run.episode), str(job.out_dir),
                                          self.runner, os.getpid()))
        with self._lock:
            process.start()
            self._live.add(process)
        writer.close()
        try:
            record = _await(reader, process, job.deadline_s)
        finally:
            reader.close()
            process.join(5)
            with self._lock:
                self._live.discard(process)
        record["wall_s"] = time.perf_counter() - start
        return record

    def _kill_all(self) -> None:
        with self._lock:
            for process in list(self._live):
                if process.is_alive():
                    process.kill()


def _locked(queue: Iterable[Job], lock: threading.Lock) -> Iterable[Job]:
    iterator = iter(queue)
    while True:
        with lock:
            job = next(iterator, None)
        if job is None:
            return
        yield job


def _await(reader: Connection, process: multiprocessing.process.BaseProcess,
           deadline_s: float) -> Record:
    """The child's record, or a timeout (after killing it), or a crash (it died silently)."""
    ready = wait([reader], timeout=deadline_s)
    if not ready:
        process.kill()
        return timeout_record(deadline_s)
    try:
        return reader.recv()
    except (EOFError, OSError):
        process.join(5)
        return {"status": "crashed", "summary": None, "error": _crash(process.exitcode)}


def timeout_record(deadline_s: float) -> Record:
    return {"status": "timeout", "summary": None,
            "error": f"killed after the wall-clock limit of {deadline_s:g} s"}


def _crash(code: int | None) -> str:
    if code is not None and code < 0:
        return f"episode process killed by signal {-code}"
    return f"episode process exited without a result (exit code {code})"


def _noop() -> None:
    pass


def _child(writer: Connection, spec: dict[str, Any], out_dir: str, runner: str,
           parent: int) -> None:
    _exit_with(parent)
    writer.send(execute(spec, out_dir, runner))
    writer.close()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)  # the record is sent, the files closed: skip tearing down the interpreter


def _exit_with(parent: int, interval_s: float = 1.0) -> None:
    """Exit when the campaign process is gone (the forkserver dies with it), no orphans."""

    def watch() -> None:
        while True:
            try:
                os.kill(parent, 0)
            except OSError:
                os._exit(1)
            time.sleep(interval_s)

    threading.Thread(target=watch, daemon=True, name="avs-parent-watch").start()
