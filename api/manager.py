"""Task life cycle: accept (bounded, idempotent), run in the worker pool, record, cancel, recover.

Also runs the synchronous plan/check jobs in their own small pool so that long episodes never
block a knowledge engineer's request.

Storage faults are survived without a restart: a task whose events cannot be written is
stopped and failed with the reason; a task that cannot be claimed stays queued; writes that
failed (a final state, a state event) wait in order. A supervisor thread retries them (and
probes the store) every `SUPERVISE_S`, runs the waiting tasks once writes work again, and
restarts any worker slot thread that died.
"""

from __future__ import annotations

import asyncio
import logging
import shutil
import threading
import time
import uuid
from collections import Counter, deque
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from api.buildings import building_spec, memory_dir, world_identity, world_text
from api.config import Settings
from api.limits import short, without_file_options
from api.schemas import TaskState
from api.security import Caller
from api.store import StorageError, TaskRecord, TaskStore
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


SUPERVISE_S = 0.5  # how often failed writes are retried and worker threads checked
MAX_ERROR = 2000  # characters of a task's `error`


class QueueFullError(Exception):
    """No room for another job; the client should retry later (HTTP 503)."""


class QuotaError(Exception):
    """The caller's key has used its quota of queued tasks or plan jobs (HTTP 429)."""


class IdempotencyConflictError(Exception):
    """The Idempotency-Key was used before with a different request body (HTTP 422)."""


class NotCancellableError(Exception):
    """The task already ended (HTTP 409)."""


class BuildingWorldError(Exception):
    """The task names a building that is another world (HTTP 422 naming `building`)."""


class BuildingBusyError(Exception):
    """The building has tasks queued or running (HTTP 409 for a forget)."""


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
        self._failures: dict[str, str] = {}  # task id -> why its storage failed (it is stopped)
        self._pending: deque[Callable[[], Any]] = deque()  # writes waiting for the store
        self._pending_lock = threading.Lock()
        self._deferred: set[str] = set()  # queued tasks whose start could not be recorded
        self._plan_jobs: Counter[str] = Counter()  # owner -> plan/check jobs in flight
        self._stopping = threading.Event()
        self._supervisor: threading.Thread | None = None
        # one task at a time per building: the task admitted to the pool, and those waiting
        self._gate = threading.Lock()
        self._admitted: dict[str, str] = {}  # building -> task id in the pool (or running)
        self._waiting: dict[str, deque[str]] = {}  # building -> queued task ids, in order

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
        self._supervisor = threading.Thread(target=self._supervise, name="avs-supervisor",
                                            daemon=True)
        self._supervisor.start()

    def stop(self) -> None:
        self._stopping.set()
        self.episodes.stop()
        self.jobs.stop()
        if self._supervisor is not None:
            self._supervisor.join(timeout=5)

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
        self, request: dict[str, Any], caller: Caller, idempotency_key: str | None,
        request_hash: str,
    ) -> Submission:
        """Queue a task; `StorageError` when the store cannot take it (nothing is queued)."""
        owner = caller.owner
        with self._lock:
            if idempotency_key is not None:
                earlier = self.store.find_by_key(owner, idempotency_key)
                if earlier is not None:
                    if earlier.request_hash != request_hash:
                        raise IdempotencyConflictError(idempotency_key)
                    return Submission(earlier, replayed=True)
            if self.store.count_state(TaskState.QUEUED) >= self.settings.queue_size:
                raise QueueFullError(f"{self.settings.queue_size} tasks already queued")
            quota = caller.max_queued
            if quota and self.store.count_state(TaskState.QUEUED, owner) >= quota:
                raise QuotaError(f"key {caller.name!r} already has {quota} queued tasks, its "
                                 "quota; retry when one has started")
            building = request.get("building")
            place = None
            if isinstance(building, str):
                place = (building, world_identity(request))
                known = self.store.building(building)
                if known is not None and known.world != place[1]:
                    raise BuildingWorldError(
                        f"building {building!r} is {world_text(known.world)}; this task "
                        f"names {world_text(place[1])} (a building is always the same "
                        f"world; forget it, DELETE /v1/buildings/{building}, to reuse its id)")
            task_id = uuid.uuid4().hex
            self.store.insert(task_id, request, owner, idempotency_key, request_hash, place)
        self._state_event(task_id, TaskState.QUEUED)
        self._enqueue(task_id, building if isinstance(building, str) else None)
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

    def _enqueue(self, task_id: str, building: str | None = None) -> None:
        """Give the task to the worker pool, or, when a task of its building is in the pool,
        keep it waiting (queued) until that one has ended (`_release`)."""
        if building is None:
            task = self.store.get(task_id)
            building = task.building if task is not None else None
        if building is not None:
            with self._gate:
                holder = self._admitted.get(building)
                if holder is not None and holder != task_id:
                    self._waiting.setdefault(building, deque()).append(task_id)
                    return
                self._admitted[building] = task_id
        self._submit(task_id, building)

    def _release(self, building: str | None, task_id: str) -> None:
        """The task of `building` in the pool has ended (or was skipped): admit the next."""
        if building is None:
            return
        with self._gate:
            if self._admitted.get(building) != task_id:
                return
            waiting = self._waiting.get(building)
            following = waiting.popleft() if waiting else None
            if waiting is not None and not waiting:
                del self._waiting[building]
            if following is None:
                del self._admitted[building]
                return
            self._admitted[building] = following
        if not self._stopping.is_set():
            self._submit(following, building)

    def building_busy(self, building: str) -> bool:
        """Whether a task of `building` is in the pool or waits for one."""
        with self._gate:
            return building in self._admitted

    def _submit(self, task_id: str, building: str | None) -> None:
        cancel = self._cancels.setdefault(task_id, threading.Event())
        output_dir = str((self.settings.tasks_dir / task_id).resolve()) + "/"
        job = Job(
            kind="episode",
            payload={},  # filled in when it starts (`_claim`)
            time_limit_s=self.settings.task_time_limit_s,
            on_event=lambda event: self._record_event(task_id, _relative(event, output_dir),
                                                      cancel),
            cancel=cancel,
        )
        job.on_start = lambda: self._claim(task_id, job)
        future = self.episodes.submit(job)
        future.add_done_callback(lambda f: self._finished(task_id, f.result(), building))

    def _episode_spec(self, task: TaskRecord) -> dict[str, Any]:
        """What the episode runner gets: the request (less any option naming a file, which
        tasks stored by older versions may hold; with `strict_labels`), its id and its own
        output folder."""
        output_dir = self.settings.tasks_dir / task.id
        output_dir.mkdir(parents=True, exist_ok=True)
        request = dict(task.request)
        if isinstance(request.get("strategy_options"), dict):
            request["strategy_options"] = without_file_options(request["strategy_options"])
        request["strict_labels"] = bool(request.get("strict_labels"))  # false: an unknown
        # target label is searched for with an uninformed prior (tasks stored before the
        # field existed lack it)
        for key in ("memory", "experience", "output_dir"):  # the service's to say, never a
            request.pop(key, None)  # request's (the schema forbids them; old rows: dropped)
        spec = {**request, "task_id": task.id, "output_dir": str(output_dir.resolve())}
        if isinstance(request.get("building"), str):
            spec.update(self._building_spec(request["building"], request.get("since_s")))
        else:
            spec.pop("since_s", None)
        if self.record:
            spec["record"] = True
        return spec

    def memory_dir(self, building: str) -> Path:
        """`DATA_DIR/buildings/ID/memory` (`buildings.memory_dir`)."""
        return memory_dir(self.settings, building)

    def _building_spec(self, building: str, since_s: Any) -> dict[str, Any]:
        """The episode spec's building keys (`buildings.building_spec`)."""
        return building_spec(self.settings, building, since_s)

    def forget(self, building: str) -> bool:
        """Forget a building: its memory files, its scope of the experience store and its
        record (its tasks and their results stay). False when it is not known;
        `BuildingBusyError` while a task of it is queued or running."""
        from avs_planner.jobs import forget_building_experience

        with self._lock:  # no task of it is submitted meanwhile
            if self.store.building(building) is None:
                return False
            live = self.store.building_live(building)
            if live or self.building_busy(building):
                raise BuildingBusyError(
                    f"building {building!r} has {live or 1} task(s) queued or running; "
                    f"cancel them or wait for them to end before forgetting it")
            folder = self.memory_dir(building).parent
            shutil.rmtree(folder, ignore_errors=True)
            if folder.exists():
                raise OSError(f"the memory of building {building!r} could not be deleted")
            forget_building_experience(str(self.settings.experience_path), building)
            return self.store.forget_building(building)

    def _claim(self, task_id: str, job: Job) -> bool:
        """queued -> running and the job's spec; False skips the job: the task is no longer
        queued, or the store cannot record the start (it waits, queued, for the store)."""
        try:
            if not self.store.claim(task_id):
                return False
        except StorageError as exc:
            log.warning("task %s cannot start now (%s); it waits for the store", task_id, exc)
            self._deferred.add(task_id)
            return False
        task = self.store.get(task_id)
        if task is None:
            return False
        try:
            job.payload = self._episode_spec(task)
        except (OSError, ValueError) as exc:
            error = f"storage error: cannot create the task's folders: {exc.strerror or exc}" \
                if isinstance(exc, OSError) else f"cannot start: {exc}"
            self._write(lambda: self._finish(task_id, TaskState.FAILED, None, error))
            return False
        self._state_event(task_id, TaskState.RUNNING, attempt=task.attempts)
        return True

    def _record_event(self, task_id: str, event: dict[str, Any],
                      cancel: threading.Event) -> None:
        """Store an episode's event; when the store fails, stop the episode (its task fails
        with the reason) rather than run on unrecorded."""
        if task_id in self._failures:
            return
        try:
            self.store.add_event(task_id, event)
        except StorageError as exc:
            log.error("task %s: %s; stopping its episode", task_id, exc)
            self._failures[task_id] = (f"{exc}: the episode's events could not be recorded, so "
                                       "it was stopped")
            cancel.set()

    def _finished(self, task_id: str, result: JobResult, building: str | None = None) -> None:
        try:
            self._record_end(task_id, result)
        finally:
            self._release(building, task_id)

    def _record_end(self, task_id: str, result: JobResult) -> None:
        try:
            self._cancels.pop(task_id, None)
            failure = self._failures.pop(task_id, None)
            if result.outcome in (JobOutcome.SHUTDOWN, JobOutcome.SKIPPED):
                return  # left 'running' (the next start accounts for it) or still queued
            if failure is not None:
                state, summary, error = TaskState.FAILED, None, failure
            else:
                state, summary, error = _task_outcome(result)
            if error:  # a building's memory named by its place in the data dir, not the path
                error = error.replace(str(self.settings.data_dir.resolve()), "DATA_DIR")
            self._write(lambda: self._finish(task_id, state, summary, error))
        except Exception:  # noqa: BLE001 - a future's callback must not fail silently
            log.exception("recording the end of task %s failed", task_id)

    def _finish(self, task_id: str, state: TaskState, summary: dict[str, Any] | None,
                error: str | None) -> None:
        if self.store.finish(task_id, state, summary, error):
            self._state_event(task_id, state, error)

    def _state_event(self, task_id: str, state: TaskState, message: str | None = None,
                     attempt: int | None = None) -> None:
        event: dict[str, Any] = {"type": "state", "state": state.value, "time": time.time()}
        if message:
            event["message"] = message
        if attempt is not None:
            event["attempt"] = attempt  # 2, 3, ...: a requeued task's events after this are new
        self._write(lambda: self.store.add_event(task_id, event))

    # -- storage faults -------------------------------------------------------------------------

    def _write(self, write: Callable[[], Any]) -> None:
        """Do a store write now, or (when the store fails, or earlier writes wait) later, in
        order, once the store takes writes again."""
        with self._pending_lock:
            if self._pending:
                self._pending.append(write)
                return
        try:
            write()
        except StorageError as exc:
            log.warning("a write waits for the store: %s", exc)
            with self._pending_lock:
                self._pending.append(write)

    def _flush(self) -> bool:
        """Do the waiting writes in order; False when the store still fails."""
        while True:
            with self._pending_lock:
                if not self._pending:
                    return True
                write = self._pending[0]
            try:
                write()
            except StorageError:
                return False
            except Exception:  # noqa: BLE001 - a bad write must not block the others
                log.exception("a waiting write failed")
            with self._pending_lock:
                self._pending.popleft()

    def degraded(self) -> str | None:
        """Why the service cannot record work now, or None when it can."""
        error = self.store.write_error
        with self._pending_lock:
            waiting = len(self._pending)
        if error is None and not waiting:
            return None
        reason = error or "storage recovered; catching up"
        if waiting:
            reason += f" ({waiting} write(s) waiting)"
        if self._deferred:
            reason += f"; {len(self._deferred)} queued task(s) wait for it"
        return reason

    def _supervise(self) -> None:
        while not self._stopping.wait(SUPERVISE_S):
            try:
                self.supervise_once()
            except Exception:  # noqa: BLE001 - the supervisor must outlive any one fault
                log.exception("supervisor check failed")

    def supervise_once(self) -> None:
        """Revive dead worker threads; retry waiting writes (or probe a failing store); once
        writes work, queue again the tasks that could not start."""
        self.episodes.revive()
        self.jobs.revive()
        with self._pending_lock:
            waiting = bool(self._pending)
        if waiting:
            if not self._flush():
                return
        elif self.store.write_error is not None and not self.store.probe():
            return
        if self._deferred:
            log.info("the store takes writes again: %d waiting task(s) queued again",
                     len(self._deferred))
            deferred, self._deferred = self._deferred, set()
            for task_id in self.store.ids_in_state(TaskState.QUEUED):
                if task_id in deferred:
                    self._enqueue(task_id)

    # -- plans and checks ---------------------------------------------------------------------

    def check_job_room(self) -> None:
        """`QueueFullError` when the plan/check queue is full."""
        if self.jobs.pending() >= self.settings.plan_queue_size:
            raise QueueFullError(f"{self.settings.plan_queue_size} plan/check jobs waiting")

    def take_plan_slot(self, caller: Caller) -> None:
        """Count a plan/check job against the caller's quota (`QuotaError` when used up);
        give it back with `free_plan_slot`."""
        with self._lock:
            quota = caller.max_plan_jobs
            if quota and self._plan_jobs[caller.owner] >= quota:
                raise QuotaError(f"key {caller.name!r} already has {quota} plan/check jobs in "
                                 "flight, its quota; retry when one has ended")
            self._plan_jobs[caller.owner] += 1

    def free_plan_slot(self, owner: str) -> None:
        with self._lock:
            self._plan_jobs[owner] -= 1
            if self._plan_jobs[owner] <= 0:
                del self._plan_jobs[owner]

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
        return (_JOB_STATES.get(result.outcome, TaskState.FAILED), None,
                short(error, MAX_ERROR) if error else error)
    value = result.value
    outcome = value.get("outcome") if isinstance(value, dict) else None
    if outcome not in _EPISODE_OUTCOMES:
        return TaskState.FAILED, None, short(f"episode runner returned no known outcome: "
                                             f"{outcome!r}", MAX_ERROR)
    return _EPISODE_OUTCOMES[outcome], value, None
