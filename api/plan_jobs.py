"""Asynchronous plan jobs (`POST /v1/plans?wait=false`): 202 at once, then poll or cancel.

A long search need not hold a connection open. Records live in memory only (a plan is cheap to
ask again, unlike an episode); the newest `kept` finished ones stay readable.
"""

from __future__ import annotations

import asyncio
import time
import uuid
from collections import OrderedDict
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field

from fastapi import HTTPException

from api.limits import bounded
from api.manager import TaskManager
from api.schemas import JobError, PlanJobPublic, PlanJobState, PlanPublic
from api.security import Caller

PlanCall = Callable[[Callable[[], bool]], Awaitable[PlanPublic]]


class NotCancellable(Exception):  # noqa: N818 - mirrors the task manager's NotCancellableError
    """The plan job already ended (HTTP 409)."""


@dataclass
class _Record:
    id: str
    owner: str
    created_at: float
    state: PlanJobState = PlanJobState.QUEUED
    finished_at: float | None = None
    result: PlanPublic | None = None
    error: JobError | None = None
    task: asyncio.Task[None] | None = field(default=None, repr=False)

    def public(self) -> PlanJobPublic:
        return PlanJobPublic(id=self.id, state=self.state, created_at=self.created_at,
                             finished_at=self.finished_at, result=self.result, error=self.error)


class PlanJobs:
    """The service's asynchronous plan jobs, by id."""

    def __init__(self, manager: TaskManager, kept: int):
        self.manager = manager
        self.kept = kept
        self._records: OrderedDict[str, _Record] = OrderedDict()

    def start(self, caller: Caller, plan: PlanCall) -> PlanJobPublic:
        """Queue `plan` (a coroutine factory given an on-start hook); `QueueFullError` if full,
        `QuotaError` when the caller's key has its quota of plan jobs in flight."""
        self.manager.check_job_room()
        self.manager.take_plan_slot(caller)
        record = _Record(uuid.uuid4().hex, caller.owner, time.time())
        self._records[record.id] = record
        record.task = asyncio.get_running_loop().create_task(self._run(record, plan))
        self._forget_old()
        return record.public()

    def _visible(self, job_id: str, caller: Caller) -> _Record | None:
        record = self._records.get(job_id)
        return record if record is not None and caller.may_see(record.owner) else None

    def get(self, job_id: str, caller: Caller) -> PlanJobPublic | None:
        """The job, if there is one the caller may see (its own; an admin key any)."""
        record = self._visible(job_id, caller)
        return record.public() if record is not None else None

    def cancel(self, job_id: str, caller: Caller) -> PlanJobPublic | None:
        """Cancel a live job (its worker is killed); `NotCancellable` when it already ended."""
        record = self._visible(job_id, caller)
        if record is None:
            return None
        if record.finished_at is not None or record.task is None or record.task.done():
            raise NotCancellable(f"plan job {job_id} already ended ({record.state.value})")
        record.task.cancel()
        self._end(record, PlanJobState.CANCELLED, error=JobError(status=409, detail="cancelled"))
        return record.public()

    async def _run(self, record: _Record, plan: PlanCall) -> None:
        def started() -> bool:
            record.state = PlanJobState.RUNNING
            return True

        try:
            result = await plan(started)
        except HTTPException as exc:
            state = PlanJobState.CANCELLED if exc.status_code == 409 else PlanJobState.FAILED
            self._end(record, state, error=JobError(status=exc.status_code,
                                                    detail=bounded(exc.detail)))
        except Exception as exc:  # noqa: BLE001 - a job must end, whatever went wrong
            self._end(record, PlanJobState.FAILED, error=JobError(
                status=500, detail=bounded(f"internal error: {type(exc).__name__}: {exc}")))
        else:
            self._end(record, PlanJobState.SUCCEEDED, result=result)

    def _end(self, record: _Record, state: PlanJobState, result: PlanPublic | None = None,
             error: JobError | None = None) -> None:
        if record.finished_at is not None:
            return
        record.state, record.result, record.error = state, result, error
        record.finished_at = time.time()
        self.manager.free_plan_slot(record.owner)

    def _forget_old(self) -> None:
        finished = [r.id for r in self._records.values() if r.finished_at is not None]
        for job_id in finished[: max(0, len(finished) - self.kept)]:
            del self._records[job_id]

    def stop(self) -> None:
        for record in self._records.values():
            if record.task is not None and not record.task.done():
                record.task.cancel()
