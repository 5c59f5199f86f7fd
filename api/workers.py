"""Worker processes (spawn context) that run jobs one at a time, killed on timeout or cancel.

A `WorkerPool` owns N slots; each slot is a thread in this process driving one child process.
A job's wall-clock limit and cancellation are enforced here, from outside the child: a stop
request first (the job may finish cleanly within the grace time), then the process is killed
and a fresh one is spawned for the next job.
"""

from __future__ import annotations

import logging
import multiprocessing
import queue
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass, field
from enum import StrEnum
from multiprocessing.connection import Connection
from typing import Any

from api.worker_process import STOP, worker_main

log = logging.getLogger("avs.api.workers")
_POLL_S = 0.05


class JobOutcome(StrEnum):
    DONE = "done"  # the job function returned `value`
    ERROR = "error"  # it raised; `error` says what
    TIMEOUT = "timeout"  # wall-clock limit hit; process killed
    CANCELLED = "cancelled"  # cancel requested; stopped or killed
    CRASHED = "crashed"  # the process died (e.g. killed by the OS)
    SHUTDOWN = "shutdown"  # the service stopped while the job ran
    SKIPPED = "skipped"  # on_start declined it (e.g. the task was cancelled while queued)


@dataclass(frozen=True)
class JobResult:
    outcome: JobOutcome
    value: Any = None
    error: str | None = None
    error_type: str | None = None


@dataclass
class Job:
    """A unit of work: `kind` is 'episode', 'plan' or 'check'; events go to `on_event`."""

    kind: str
    payload: dict[str, Any]
    time_limit_s: float
    on_start: Callable[[], bool] = lambda: True  # False: skip the job (e.g. cancelled)
    on_event: Callable[[dict[str, Any]], None] = lambda event: None
    cancel: threading.Event = field(default_factory=threading.Event)
    future: Future[JobResult] = field(default_factory=Future)
    grace_s: float | None = None  # after a cancel, time to stop before a kill; None: the pool's


class _Slot:
    """One child process and the thread that feeds it."""

    def __init__(self, pool: WorkerPool, index: int):
        self.pool = pool
        self.index = index
        self.process: multiprocessing.process.BaseProcess | None = None
        self.conn: Connection | None = None

    def ensure_process(self) -> Connection:
        if self.process is not None and self.process.is_alive() and self.conn is not None:
            return self.conn
        self.kill()
        ctx = multiprocessing.get_context("spawn")
        parent, child = ctx.Pipe(duplex=True)
        self.process = ctx.Process(
            target=worker_main,
            args=(child, self.pool.memory_limit_mb, self.pool.runners, self.pool.preload,
                  self.pool.nice),
            name=f"avs-{self.pool.name}-{self.index}",
            daemon=True,
        )
        self.process.start()
        child.close()
        self.conn = parent
        return parent

    def kill(self) -> None:
        if self.process is not None and self.process.is_alive():
            self.process.kill()
            self.process.join(timeout=5)
        if self.conn is not None:
            self.conn.close()
        self.process, self.conn = None, None

    def run(self, job: Job) -> JobResult:
        try:
            conn = self.ensure_process()
            conn.send((job.kind, job.payload))
        except (OSError, EOFError) as exc:
            self.kill()
            return JobResult(JobOutcome.CRASHED, error=f"could not start a worker: {exc}")
        return self._watch(job, conn, time.monotonic() + job.time_limit_s)

    def _watch(self, job: Job, conn: Connection, deadline: float) -> JobResult:
        stop_sent_at: float | None = None
        while True:
            if self.pool.stopping.is_set():
                self.kill()
                return JobResult(JobOutcome.SHUTDOWN, error="service stopped")
            if job.cancel.is_set() and stop_sent_at is None:
                stop_sent_at = time.monotonic()
                _send_quietly(conn, STOP)
            grace = self.pool.grace_s if job.grace_s is None else job.grace_s
            if stop_sent_at is not None and time.monotonic() - stop_sent_at >= grace:
                self.kill()
                return JobResult(JobOutcome.CANCELLED, error="cancelled; worker killed")
            if time.monotonic() > deadline:
                self.kill()
                limit = f"{job.time_limit_s:g}"
                return JobResult(JobOutcome.TIMEOUT, error=f"wall-clock limit {limit} s exceeded")
            result = self._receive(job, conn)
            if result is not None:
                if stop_sent_at is not None and result.outcome is not JobOutcome.CRASHED:
                    return JobResult(JobOutcome.CANCELLED, result.value, "cancelled")
                return result

    def _receive(self, job: Job, conn: Connection) -> JobResult | None:
        try:
            if not conn.poll(_POLL_S):
                return None
            message = conn.recv()
        except (EOFError, OSError):
            code = self.process.exitcode if self.process is not None else None
            self.kill()
            return JobResult(JobOutcome.CRASHED, error=_crash_message(code))
        if message[0] == "event":
            job.on_event(message[1])
            return None
        if message[0] == "result":
            return JobResult(JobOutcome.DONE, value=message[1])
        return JobResult(JobOutcome.ERROR, error=message[2], error_type=message[1])

    def loop(self) -> None:
        if self.pool.warm:
            try:
                self.ensure_process()  # warm start: the first job does not pay for the spawn
            except Exception:  # noqa: BLE001 - the first job retries and reports it
                log.exception("could not pre-start worker %s", self.index)
        while True:
            job = self.pool.jobs.get()
            if job is None or self.pool.stopping.is_set():
                if job is not None and job.future.set_running_or_notify_cancel():
                    job.future.set_result(JobResult(JobOutcome.SHUTDOWN, error="service stopped"))
                return
            if not job.future.set_running_or_notify_cancel():
                continue
            if job.cancel.is_set():  # cancelled while it waited: never started
                job.future.set_result(JobResult(JobOutcome.CANCELLED, error="cancelled"))
                continue
            try:
                started = job.on_start()
            except Exception:  # noqa: BLE001 - e.g. the store failed: skip it, keep serving
                log.exception("worker slot %s: starting a job failed", self.index)
                started = False
            if not started:
                job.future.set_result(JobResult(JobOutcome.SKIPPED))
                continue
            try:
                result = self.run(job)
            except Exception as exc:  # noqa: BLE001 - a slot thread must never die silently
                log.exception("worker slot %s failed", self.index)
                self.kill()  # its process may still be busy with this job
                result = JobResult(JobOutcome.CRASHED, error=f"internal error: {exc}")
            job.future.set_result(result)


def _send_quietly(conn: Connection, message: Any) -> None:
    try:
        conn.send(message)
    except (OSError, EOFError):
        pass


def _crash_message(code: int | None) -> str:
    if code is not None and code < 0:
        return f"worker process killed by signal {-code} (memory limit or the OS)"
    return f"worker process exited unexpectedly (exit code {code})"


class WorkerPool:
    """N worker processes fed from one FIFO of jobs."""

    def __init__(
        self, name: str, size: int, memory_limit_mb: int, runners: dict[str, str], grace_s: float,
        preload: tuple[str, ...] = (), nice: int = 0, warm: bool = True,
    ):
        self.name = name
        self.warm = warm
        self.preload = preload
        self.nice = nice
        self.memory_limit_mb = memory_limit_mb
        self.runners = runners  # job kind -> 'module:function' (defaults: JOB_FUNCTIONS)
        self.grace_s = grace_s
        self.jobs: queue.Queue[Job | None] = queue.Queue()
        self.stopping = threading.Event()
        self._slots = [_Slot(self, i) for i in range(size)]
        self._threads: list[threading.Thread] = []

    @property
    def size(self) -> int:
        return len(self._slots)

    def start(self) -> None:
        for slot in self._slots:
            self._threads.append(self._thread(slot))

    def _thread(self, slot: _Slot) -> threading.Thread:
        thread = threading.Thread(target=slot.loop, name=f"avs-{self.name}-slot", daemon=True)
        thread.start()
        return thread

    def revive(self) -> int:
        """Start a fresh thread for every slot whose thread died (a bug: it is logged), so the
        pool keeps serving without a restart; returns how many were revived."""
        if self.stopping.is_set() or not self._threads:
            return 0
        revived = 0
        for i, thread in enumerate(self._threads):
            if not thread.is_alive():
                log.error("worker slot %s of %s had stopped; starting it again", i, self.name)
                self._slots[i].kill()
                self._threads[i] = self._thread(self._slots[i])
                revived += 1
        return revived

    def submit(self, job: Job) -> Future[JobResult]:
        self.jobs.put(job)
        return job.future

    def alive(self) -> bool:
        """Whether every slot thread is still serving (false before start and after stop)."""
        return bool(self._threads) and all(t.is_alive() for t in self._threads)

    def pending(self) -> int:
        return self.jobs.qsize()

    def stop(self) -> None:
        """Stop feeding jobs, kill the children, and resolve waiting futures as SHUTDOWN."""
        self.stopping.set()
        for _ in self._threads:
            self.jobs.put(None)
        for thread in self._threads:
            thread.join(timeout=10)
        for slot in self._slots:
            slot.kill()
        self._drain()

    def _drain(self) -> None:
        while True:
            try:
                job = self.jobs.get_nowait()
            except queue.Empty:
                return
            if job is not None and job.future.set_running_or_notify_cancel():
                job.future.set_result(JobResult(JobOutcome.SHUTDOWN, error="service stopped"))
