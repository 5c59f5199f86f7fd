"""Task life cycle: accept (bounded, idempotent), run in the worker pool, record, cancel, recover.

Also runs the synchronous plan/check jobs in their own small pool so that long episodes never
block a knowledge engineer's request.
"""

from __future__ import annotations

import asyncio
import logging
import threading
import time
import uuid
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from api.config import Settings
from api.schemas import TaskState
from api.store import TaskRecord, TaskStore
from api.worker_process import PRELOAD_JOBS, resolve
from api.workers import Job, JobOutcome, JobResult, WorkerPool

log = logging.getLogger("avs.api.tasks")

_EPISODE_OUTCOMES = {
    "found": TaskState.SUCCEEDED,
    "gave_up": TaskState.GAVE_UP,
    "timeout": TaskState.TIMEOUT,
}
_JOB_STATES = {
    JobOutcome.TIMEOUT: TaskState.TIMEOUT,
    JobOutcome.CANCELLED: TaskState.CANCELLED,
    JobOutcome.ERROR: TaskState.FAILED,
    JobOutcome.CRASHED: TaskState.FAILED,
}


TaskChecker = Callable[[dict[str, Any], Path | None], list[Any]]  # -> [FieldProblem(field, msg)]


class QueueFullError(Exception):
    """No room for another job; the client should retry later (HTTP 503)."""


class IdempotencyConflictError(Exception):
    """The Idempotency-Key was used before with a different request body (HTTP 422)."""


class NotCancellableError(Exception):
    """The task already ended (HTTP 409)."""


class ClientGoneError(Exception):
    """The client of a synchronous plan/check disconnected; its job was cancelled."""


class StoppingError(Exception):
    """The service is stopping; the job was cancelled (HTTP 503, retry after the restart)."""


_DISCONNECT_POLL_S = 0.25


@dataclass(frozen=True)
class Submission:
    task: TaskRecord
    replayed: bool  # True: the Idempotency-Key matched an earlier identical request


class TaskManager:
    """Owns the store and both worker pools; every route goes through it."""

    def __init__(self, settings: Settings, store: TaskStore,
                 draining: threading.Event | None = None):
        self.settings = settings
        self.store = store
        self.draining = draining or threading.Event()  # set when the service begins to stop
        self.episodes = _episode_pool(settings)
        self.jobs = WorkerPool(
            "jobs", settings.plan_workers, settings.memory_limit_mb, {"plan": settings.plan_runner},
            settings.cancel_grace_s, preload=PRELOAD_JOBS if settings.preload_planner else (),
            nice=settings.worker_nice, warm=settings.preload_planner,
        )
        self._cancels: dict[str, threading.Event] = {}
        self._lock = threading.Lock()
        self.task_checker: TaskChecker | None = None
        self.record = settings.records()

    # -- life cycle -------------------------------------------------------------------------

    def start(self) -> None:
        """Account for tasks a previous run left behind, then start the workers."""
        if self.settings.task_checker:
            self.task_checker = resolve(self.settings.task_checker)  # imported now, not per call
        self._recover()
        self.episodes.start()
        self.jobs.start()
        for task_id in self.store.ids_in_state(TaskState.QUEUED):
            self._enqueue(task_id)

    def stop(self) -> None:
        self.episodes.stop()
        self.jobs.stop()

    def _recover(self) -> None:
        for task_id in self.store.ids_in_state(TaskState.RUNNING):
            if self.settings.on_restart == "requeue":
                self.store.requeue(task_id)
                self._state_event(task_id, TaskState.QUEUED, "requeued after a service restart; "
                                  "its next run starts again from the beginning")
                log.warning("task %s was running when the service stopped: requeued", task_id)
            else:
                message = "interrupted: the service stopped while the task was running"
                self.store.finish(task_id, TaskState.FAILED, None, message)
                self._state_event(task_id, TaskState.FAILED, message)
                log.warning("task %s was running when the service stopped: failed", task_id)

    # -- tasks ------------------------------------------------------------------------------

    def submit(
        self, request: dict[str, Any], owner: str, idempotency_key: str | None, request_hash: str
    ) -> Submission:
        with self._lock:
            if idempotency_key is not None:
                earlier = self.store.find_by_key(owner, idempotency_key)
                if earlier is not None:
                    if earlier.request_hash != request_hash:
                        raise IdempotencyConflictError(idempotency_key)
                    return Submission(earlier, replayed=True)
            if self.store.count_state(TaskState.QUEUED) >= self.settings.queue_size:
                raise QueueFullError(f"{self.settings.queue_size} tasks already queued")
            task_id = uuid.uuid4().hex
            self.store.insert(task_id, request, owner, idempotency_key, request_hash)
        self._state_event(task_id, TaskState.QUEUED)
        self._enqueue(task_id)
        task = self.store.get(task_id)
        assert task is not None
        return Submission(task, replayed=False)

    def cancel(self, task_id: str) -> TaskRecord | None:
        """Cancel a queued task at once, or ask a running one to stop (killed after a grace)."""
        task = self.store.get(task_id)
        if task is None:
            return None
        if task.state.terminal:
            raise NotCancellableError(f"task {task_id} already ended ({task.state.value})")
        if self.store.finish(task_id, TaskState.CANCELLED, None, "cancelled before it started",
                             only_from=(TaskState.QUEUED,)):
            self._state_event(task_id, TaskState.CANCELLED, "cancelled before it started")
        else:
            event = self._cancels.get(task_id)
            if event is not None:
                event.set()
        return self.store.get(task_id)

    def _enqueue(self, task_id: str) -> None:
        task = self.store.get(task_id)
        if task is None:
            return
        cancel = self._cancels.setdefault(task_id, threading.Event())
        output_dir = str((self.settings.tasks_dir / task_id).resolve()) + "/"
        job = Job(
            kind="episode",
            payload=self._episode_spec(task),
            time_limit_s=self.settings.task_time_limit_s,
            on_start=lambda: self._claim(task_id),
            on_event=lambda event: self.store.add_event(task_id, _relative(event, output_dir)),
            cancel=cancel,
        )
        future = self.episodes.submit(job)
        future.add_done_callback(lambda f: self._finished(task_id, f.result()))

    def _episode_spec(self, task: TaskRecord) -> dict[str, Any]:
        output_dir = self.settings.tasks_dir / task.id
        output_dir.mkdir(parents=True, exist_ok=True)
        spec = {**task.request, "task_id": task.id, "output_dir": str(output_dir.resolve())}
        if self.record:
            spec["record"] = True
        return spec

    def _claim(self, task_id: str) -> bool:
        if not self.store.claim(task_id):
            return False
        task = self.store.get(task_id)
        attempt = task.attempts if task is not None else 1
        self._state_event(task_id, TaskState.RUNNING, attempt=attempt)
        return True

    def _finished(self, task_id: str, result: JobResult) -> None:
        self._cancels.pop(task_id, None)
        if result.outcome in (JobOutcome.SHUTDOWN, JobOutcome.SKIPPED):
            return  # left 'running'; the next start accounts for it (fail or requeue)
        state, summary, error = _task_outcome(result)
        if self.store.finish(task_id, state, summary, error):
            self._state_event(task_id, state, error)

    def _state_event(self, task_id: str, state: TaskState, message: str | None = None,
                     attempt: int | None = None) -> None:
        event: dict[str, Any] = {"type": "state", "state": state.value, "time": time.time()}
        if message:
            event["message"] = message
        if attempt is not None:
            event["attempt"] = attempt  # 2, 3, ...: a requeued task's events after this are new
        self.store.add_event(task_id, event)

    # -- plans and checks ---------------------------------------------------------------------

    def check_job_room(self) -> None:
        """`QueueFullError` when the plan/check queue is full."""
        if self.jobs.pending() >= self.settings.plan_queue_size:
            raise QueueFullError(f"{self.settings.plan_queue_size} plan/check jobs waiting")

    async def run_job(
        self, kind: str, payload: dict[str, Any],
        disconnected: Callable[[], Awaitable[bool]] | None = None,
        on_start: Callable[[], bool] = lambda: True,
    ) -> JobResult:
        """Run a plan/check job in the job pool and wait for it without blocking the loop.

        The job is cancelled (its process killed at once) when the waiting coroutine is
        cancelled, `disconnected()` turns true (`ClientGoneError`) or the service begins to stop
        (`StoppingError`)."""
        self.check_job_room()
        job = Job(kind=kind, payload=payload, time_limit_s=self.settings.plan_time_limit_s,
                  on_start=on_start, grace_s=0.0)
        waiting = asyncio.wrap_future(self.jobs.submit(job))
        try:
            while True:
                done, _ = await asyncio.wait({waiting}, timeout=_DISCONNECT_POLL_S)
                if done:
                    return waiting.result()
                if self.draining.is_set():
                    raise StoppingError(kind)
                if disconnected is not None and await disconnected():
                    raise ClientGoneError(kind)
        except (asyncio.CancelledError, ClientGoneError, StoppingError):
            job.cancel.set()  # the client went away: free the worker too
            raise

    def counts(self) -> tuple[int, int]:
        return self.store.count_state(TaskState.QUEUED), self.store.count_state(TaskState.RUNNING)


def _relative(event: dict[str, Any], root: str) -> dict[str, Any]:
    """The event with paths inside the task's own directory made relative to it (clients get
    `timeout-1.pddl`, never the server's file system layout)."""
    return {k: v[len(root):] if isinstance(v, str) and v.startswith(root) else v
            for k, v in event.items()}


def _episode_pool(settings: Settings) -> WorkerPool:
    """Local worker processes, or Ray tasks when the settings name a Ray cluster."""
    if settings.ray_address:
        from api.ray_pool import RayWorkerPool

        return RayWorkerPool("episodes", settings.workers, settings.ray_address,
                             settings.episode_runner, settings.cancel_grace_s)
    return WorkerPool(
        "episodes", settings.workers, settings.memory_limit_mb,
        {"episode": settings.episode_runner},
        settings.cancel_grace_s, nice=settings.worker_nice, warm=settings.warm_workers,
    )


def _task_outcome(result: JobResult) -> tuple[TaskState, dict[str, Any] | None, str | None]:
    """The terminal state, summary and error of a task from its job's result."""
    if result.outcome is not JobOutcome.DONE:
        error = result.error
        if result.error_type:
            error = f"{result.error_type}: {error}"
        return _JOB_STATES.get(result.outcome, TaskState.FAILED), None, error
    value = result.value
    outcome = value.get("outcome") if isinstance(value, dict) else None
    if outcome not in _EPISODE_OUTCOMES:
        return TaskState.FAILED, None, f"episode runner returned no known outcome: {outcome!r}"
    return _EPISODE_OUTCOMES[outcome], value, None
