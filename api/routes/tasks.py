"""/tasks: submit a search, list and read tasks, stream their events, cancel, trajectory picture."""

from __future__ import annotations

import asyncio
import hashlib
import json
from collections.abc import AsyncIterable
from typing import Annotated

from fastapi import APIRouter, Header, HTTPException, Query, Response, status
from fastapi.responses import FileResponse
from fastapi.sse import EventSourceResponse, ServerSentEvent

from api.deps import ManagerDep, SettingsDep, StoreDep, TaskDep, TaskId, WriteAccess
from api.manager import IdempotencyConflictError, NotCancellableError, QueueFullError
from api.schemas import Message, TaskCreate, TaskPublic, TasksPublic, TaskState
from api.store import TaskRecord
from api.worlds import list_worlds, world_file_problem

router = APIRouter(prefix="/tasks", tags=["tasks"])

_EVENT_POLL_S = 0.2
_ERRORS = {
    401: {"model": Message, "description": "missing or wrong X-API-Key"},
    429: {"model": Message, "description": "rate limit exceeded"},
}


def to_public(task: TaskRecord, full: bool = True) -> TaskPublic:
    """The client's view; lists (`full=False`) elide inline world files to their size."""
    request = task.request
    if not full and isinstance(request.get("world_file"), str):
        request = {**request, "world_file": f"<inline, {len(request['world_file'])} chars>"}
    return TaskPublic(
        id=task.id, state=task.state, request=request, created_at=task.created_at,
        started_at=task.started_at, finished_at=task.finished_at, summary=task.result,
        error=task.error, events=task.events,
    )


def _invalid(field: str, message: str) -> HTTPException:
    """A 422 shaped like FastAPI's own validation errors, naming the field."""
    detail = [{"type": "value_error", "loc": ["body", field], "msg": message}]
    return HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, detail=detail)


def _check_world(body: TaskCreate, settings: SettingsDep) -> None:
    if body.world_file is not None:
        problem = world_file_problem(body.world_file)
        if problem:
            raise _invalid("world_file", problem)
        return
    names = [w.name for w in list_worlds(settings.worlds_dir)]
    if body.world not in names:
        known = ", ".join(names) or "none installed"
        raise _invalid("world", f"unknown world {body.world!r}; built-in worlds: {known}")


@router.post(
    "",
    status_code=status.HTTP_202_ACCEPTED,
    responses={**_ERRORS, 503: {"model": Message, "description": "queue full"}},
)
def create_task(
    body: TaskCreate,
    response: Response,
    owner: WriteAccess,
    manager: ManagerDep,
    settings: SettingsDep,
    idempotency_key: Annotated[str | None, Header(max_length=200)] = None,
) -> TaskPublic:
    """Queue a search for `target`; 202 with the task (poll it or stream its events)."""
    _check_world(body, settings)
    request = body.model_dump(mode="json")
    digest = hashlib.sha256(json.dumps(request, sort_keys=True).encode()).hexdigest()
    try:
        submission = manager.submit(request, owner, idempotency_key, digest)
    except IdempotencyConflictError as exc:
        raise HTTPException(
            status.HTTP_422_UNPROCESSABLE_CONTENT,
            detail=f"Idempotency-Key {exc} was already used with a different request body",
        ) from exc
    except QueueFullError as exc:
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE, detail=f"task queue is full ({exc}); retry later",
            headers={"Retry-After": "5"},
        ) from exc
    if submission.replayed:
        response.headers["Idempotent-Replayed"] = "true"
    response.headers["Location"] = f"/v1/tasks/{submission.task.id}"
    return to_public(submission.task)


@router.get("")
def list_tasks(
    store: StoreDep,
    state: TaskState | None = None,
    limit: Annotated[int, Query(ge=1, le=200)] = 50,
    offset: Annotated[int, Query(ge=0, le=1_000_000)] = 0,
) -> TasksPublic:
    """Tasks, newest first, optionally only those in one state."""
    tasks, count = store.page(state, limit, offset)
    return TasksPublic(data=[to_public(t, full=False) for t in tasks], count=count)


@router.get("/{task_id}", responses={404: {"model": Message}})
async def read_task(task: TaskDep) -> TaskPublic:
    """One task: its state, request, and summary (once it ended) or error."""
    return to_public(task)


@router.delete(
    "/{task_id}",
    responses={**_ERRORS, 404: {"model": Message}, 409: {"model": Message}},
)
def cancel_task(task_id: TaskId, owner: WriteAccess, manager: ManagerDep) -> TaskPublic:
    """Cancel: a queued task ends at once; a running episode is asked to stop and killed after
    a grace time, so the task returned may still say `running` for that long."""
    try:
        task = manager.cancel(task_id)
    except NotCancellableError as exc:
        raise HTTPException(status.HTTP_409_CONFLICT, detail=str(exc)) from exc
    if task is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no task with id {task_id}")
    return to_public(task)


@router.get(
    "/{task_id}/events", response_class=EventSourceResponse, responses={404: {"model": Message}}
)
async def stream_events(
    task: TaskDep,
    store: StoreDep,
    last_event_id: Annotated[int | None, Header(alias="Last-Event-ID", ge=0, le=2**62)] = None,
) -> AsyncIterable[ServerSentEvent]:
    """The task's events as Server-Sent Events, from after `Last-Event-ID`; ends with the task."""
    after = last_event_id or 0
    while True:
        events = store.events_after(task.id, after)
        for event in events:
            after = event.seq
            kind = str(event.data.get("type", "message")).replace("\n", " ")
            yield ServerSentEvent(data=event.data, id=str(event.seq), event=kind)
        if events:
            continue
        current = store.get(task.id)
        if current is None or (current.state.terminal and not store.events_after(task.id, after)):
            return
        await asyncio.sleep(_EVENT_POLL_S)


@router.get(
    "/{task_id}/trajectory.png",
    response_class=FileResponse,
    responses={200: {"content": {"image/png": {}}}, 404: {"model": Message}},
)
async def read_trajectory(task: TaskDep, settings: SettingsDep) -> FileResponse:
    """The episode's trajectory picture, once the runner has drawn one."""
    path = settings.tasks_dir / task.id / "trajectory.png"
    if not path.is_file():
        raise HTTPException(
            status.HTTP_404_NOT_FOUND,
            detail=f"task {task.id} has no trajectory picture yet (state: {task.state.value})",
        )
    return FileResponse(path, media_type="image/png")
