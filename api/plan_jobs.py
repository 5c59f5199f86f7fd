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

from api.manager import TaskManager
from api.schemas import JobError, PlanJobPublic, PlanJobState, PlanPublic

PlanCall = Callable[[Callable[[], bool]], Awaitable[PlanPublic]]


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

    def start(self, owner: str, plan: PlanCall) -> PlanJobPublic:
        """Queue `plan` (a coroutine factory given an on-start hook); `QueueFullError` if full."""
        self.manager.check_job_room()
        record = _Record(uuid.uuid4().hex, owner, time.time())
        self._records[record.id] = record
        record.task = asyncio.get_running_loop().create_task(self._run(record, plan))
        self._forget_old()
        return record.public()

    def get(self, job_id: str) -> PlanJobPublic | None:
        record = self._records.get(job_id)
        return record.public() if record is not None else None

    def cancel(self, job_id: str) -> PlanJobPublic | None:
        """Cancel a live job (its worker is killed); a finished one is returned unchanged."""
        record = self._records.get(job_id)
        if record is None:
            return None
        if record.task is not None and not record.task.done():
            record.task.cancel()
            self._end(record, PlanJobState.CANCELLED, error=JobError(status=409,
                                                                     detail="cancelled"))
        return record.public()

    async def _run(self, record: _Record, plan: PlanCall) -> None:
        def started() -> bool:
            record.state = PlanJobState.RUNNING
            return True

        try:
            result = await plan(started)
        except HTTPException as exc:
            state = PlanJobState.CANCELLED if exc.status_code == 409 else PlanJobState.FAILED
            self._end(record, state, error=JobError(status=exc.status_code, detail=exc.detail))
        else:
            self._end(record, PlanJobState.SUCCEEDED, result=result)

    def _end(self, record: _Record, state: PlanJobState, result: PlanPublic | None = None,
             error: JobError | None = None) -> None:
        if record.finished_at is not None:
            return
        record.state, record.result, record.error = state, result, error
        record.finished_at = time.time()

    def _forget_old(self) -> None:
        finished = [r.id for r in self._records.values() if r.finished_at is not None]
        for job_id in finished[: max(0, len(finished) - self.kept)]:
            del self._records[job_id]

    def stop(self) -> None:
        for record in self._records.values():
            if record.task is not None and not record.task.done():
                record.task.cancel()
