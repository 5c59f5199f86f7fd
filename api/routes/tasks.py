"""/tasks: submit a search, list and read tasks, stream their events, cancel; the episode's
trajectory picture and Rerun recording."""

from __future__ import annotations

import asyncio
import hashlib
import json
from collections.abc import AsyncIterable
from typing import Annotated, Any

from fastapi import APIRouter, Header, HTTPException, Query, Request, Response, status
from fastapi.responses import FileResponse
from fastapi.sse import EventSourceResponse, ServerSentEvent

from api.deps import (
    ManagerDep,
    SettingsDep,
    StoreDep,
    TaskCheckerDep,
    TaskDep,
    TaskId,
    WriteAccess,
)
from api.manager import IdempotencyConflictError, NotCancellableError, QueueFullError
from api.schemas import TOO_LARGE, Message, TaskCreate, TaskPublic, TasksPublic, TaskState
from api.store import TaskRecord
from api.worlds import world_file_problem, world_files, world_path

router = APIRouter(prefix="/tasks", tags=["tasks"])

_EVENT_POLL_S = 0.2
_RETRY_MS = 5000
_SHUTDOWN = {"type": "shutdown", "message": "the service is stopping; reconnect with "
             "Last-Event-ID set to the last id received to resume"}
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
        error=task.error, events=task.events, attempts=task.attempts,
    )


def _invalid(problems: list[tuple[str, str]], where: str = "body") -> HTTPException:
    """A 422 shaped like FastAPI's own validation errors, naming each field."""
    detail = [{"type": "value_error", "loc": [where, field], "msg": message}
              for field, message in problems]
    return HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, detail=detail)


def _check_task(body: TaskCreate, request: dict, settings: SettingsDep,
                checker: TaskCheckerDep) -> None:
    """422 for a task that could never run: unknown world, then whatever the checker finds."""
    path = None
    if body.world_file is not None:
        problem = world_file_problem(body.world_file)
        if problem:
            raise _invalid([("world_file", problem)])
    elif body.world is not None:
        path = world_path(settings.worlds_dir, str(body.world))
        if path is None:
            known = ", ".join(f.stem for f in world_files(settings.worlds_dir)) or "none"
            raise _invalid([("world", f"unknown world {body.world!r}; built-in worlds: {known}")])
    if checker is not None:
        problems = checker(request, path)
        if problems:
            raise _invalid([(p.field, p.message) for p in problems])


@router.post(
    "",
    status_code=status.HTTP_202_ACCEPTED,
    responses={**_ERRORS, **TOO_LARGE, 503: {"model": Message, "description": "queue full"}},
)
def create_task(
    body: TaskCreate,
    response: Response,
    owner: WriteAccess,
    manager: ManagerDep,
    settings: SettingsDep,
    checker: TaskCheckerDep,
    idempotency_key: Annotated[str | None, Header(min_length=1, max_length=200)] = None,
) -> TaskPublic:
    """Queue a search for `target`; 202 with the task (poll it or stream its events).

    422 when any field is wrong, checked now against the world and the knowledge base."""
    request = body.model_dump(mode="json")
    _check_task(body, request, settings, checker)
    digest = hashlib.sha256(json.dumps(request, sort_keys=True).encode()).hexdigest()
    try:
        submission = manager.submit(request, owner, idempotency_key, digest)
    except IdempotencyConflictError as exc:
        message = f"Idempotency-Key {exc} was already used with a different request body"
        raise _invalid([("idempotency-key", message)], where="header") from exc
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
    request: Request,
    last_event_id: Annotated[int | None, Header(alias="Last-Event-ID", ge=0, le=2**62)] = None,
) -> AsyncIterable[ServerSentEvent]:
    """The task's events as Server-Sent Events, from after `Last-Event-ID`; ends with the task,
    or with a `shutdown` event (no id) when the service stops: reconnect with Last-Event-ID."""
    after = last_event_id or 0
    draining = request.app.state.draining
    while True:
        if draining.is_set():
            yield ServerSentEvent(data=_SHUTDOWN, event="shutdown", retry=_RETRY_MS)
            return
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


@router.head("/{task_id}/recording.rrd", include_in_schema=False)
@router.get(
    "/{task_id}/recording.rrd",
    response_class=FileResponse,
    responses={200: {"content": {"application/octet-stream": {}}}, 404: {"model": Message}},
)
async def read_recording(task: TaskDep, settings: SettingsDep) -> FileResponse:
    """The episode's Rerun recording (open it with `rerun FILE` or `avs view FILE`), once it
    has ended; the service records when the viewer extra is installed (or AVS_RECORD=1)."""
    path = settings.tasks_dir / task.id / "recording.rrd"
    if not task.state.terminal or not path.is_file():
        why = ("it has not ended yet" if not task.state.terminal else
               "this service does not record episodes (install the viewer extra, "
               "pip install 'avs-planner[viewer]', or set AVS_RECORD=1)"
               if not settings.records() else "its episode left none")
        raise HTTPException(
            status.HTTP_404_NOT_FOUND,
            detail=f"task {task.id} has no recording (state: {task.state.value}): {why}",
        )
    return FileResponse(path, media_type="application/octet-stream",
                        filename=f"{task.id}.rrd")


@router.get("/{task_id}/explanation", responses={404: {"model": Message}})
def read_explanation(task: TaskDep, settings: SettingsDep) -> dict[str, Any]:
    """Why the episode went as it did: the assumption ledger (every assumption its plans used,
    with its probabilities, and whether and by which observation it was confirmed or refuted),
    the reason for every replan, and for a give-up the room hypotheses tried; `avs explain`
    prints the same as text. Available once the task has ended."""
    from avs_planner.episode.explain import FILE_NAME, ExplainError, load

    folder = settings.tasks_dir / task.id
    if not task.state.terminal:
        raise HTTPException(
            status.HTTP_404_NOT_FOUND,
            detail=f"task {task.id} has no explanation yet: it is {task.state.value}; the "
            f"explanation is written when the episode ends",
        )
    if not (folder / FILE_NAME).is_file() and not (folder / "trace.jsonl").is_file():
        raise HTTPException(
            status.HTTP_404_NOT_FOUND,
            detail=f"task {task.id} has no explanation (state: {task.state.value}): its "
            f"episode left no trace" + (f" ({task.error})" if task.error else ""),
        )
    try:
        return load(folder)  # explanation.json, or rebuilt from the trace (e.g. cancelled)
    except ExplainError as exc:
        raise HTTPException(
            status.HTTP_404_NOT_FOUND,
            detail=f"task {task.id} has no readable explanation: {exc}".replace(
                str(folder), f"task {task.id}"),
        ) from exc
