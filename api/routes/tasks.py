"""/tasks: submit a search, list and read tasks, stream their events, cancel; the episode's
trajectory picture and Rerun recording."""

from __future__ import annotations

import asyncio
import hashlib
import json
import logging
import sqlite3
import time
from collections.abc import AsyncIterator
from typing import Annotated, Any

from fastapi import APIRouter, Header, HTTPException, Query, Request, Response, status
from fastapi.responses import FileResponse, StreamingResponse
from fastapi.sse import KEEPALIVE_COMMENT, format_sse_event

from api.deps import (
    ManagerDep,
    ReadAccess,
    SettingsDep,
    StoreDep,
    TaskCheckerDep,
    TaskDep,
    TaskId,
    WriteAccess,
    visible_task,
)
from api.limits import file_option_problems, short
from api.manager import (
    BuildingWorldError,
    IdempotencyConflictError,
    NotCancellableError,
    QueueFullError,
    QuotaError,
)
from api.schemas import (
    TOO_LARGE,
    Message,
    TargetPublic,
    TaskCreate,
    TaskFormPublic,
    TaskPublic,
    TasksPublic,
    TaskState,
)
from api.store import StorageError, TaskRecord
from api.worlds import world_files, world_path

router = APIRouter(prefix="/tasks", tags=["tasks"])
log = logging.getLogger("avs.api.tasks")

_EVENT_POLL_S = 0.2
_KEEPALIVE_S = 15.0  # a comment line after this long without an event (proxies drop idle ones)
_RETRY_MS = 5000
_SHUTDOWN = {"type": "shutdown", "message": "the service is stopping; reconnect with "
             "Last-Event-ID set to the last id received to resume"}
_JSON_MESSAGE = {"application/json": {"schema": {"$ref": "#/components/schemas/Message"}}}
_READ_ERRORS: dict[int | str, dict[str, Any]] = {
    401: {"model": Message, "description": "missing or wrong X-API-Key (when the service has "
          "keys and reads are not open)"},
}
_ERRORS: dict[int | str, dict[str, Any]] = {
    401: {"model": Message, "description": "missing or wrong X-API-Key"},
    403: {"model": Message, "description": "the key's role may not do this (e.g. a read key)"},
    429: {"model": Message, "description": "rate limit or the key's quota exceeded"},
    503: {"model": Message, "description": "queue full, or the store takes no writes now "
          "(see /v1/health)"},
}


def to_public(task: TaskRecord, full: bool = True) -> TaskPublic:
    """The client's view; lists (`full=False`) elide inline world files to their size. The
    task's form comes from its request, each target's part (a task of several) from its
    summary."""
    request = task.request
    if not full and isinstance(request.get("world_file"), str):
        request = {**request, "world_file": f"<inline, {len(request['world_file'])} chars>"}
    return TaskPublic(
        id=task.id, state=task.state, request=request,
        task=TaskFormPublic.of_request(task.request), targets=TargetPublic.of_summary(
            task.result), created_at=task.created_at,
        started_at=task.started_at, finished_at=task.finished_at, summary=task.result,
        error=task.error, events=task.events, attempts=task.attempts,
    )


def _invalid(problems: list[tuple[str, str]], where: str = "body") -> HTTPException:
    """A 422 shaped like FastAPI's own validation errors, naming each field (a dotted field
    is a path: `strategy_options.learn_file`)."""
    detail = [{"type": "value_error", "loc": [where, *field.split(".", 1)],
               "msg": short(message)} for field, message in problems]
    return HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, detail=detail)


def _unknown_label(problem: Any) -> bool:
    return problem.field in ("target", "targets") and "unknown object label" in problem.message


def _check_task(body: TaskCreate, request: dict, settings: SettingsDep,
                checker: TaskCheckerDep) -> None:
    """422 for a task that could never run: an option naming a file, an unknown world, then
    whatever the checker finds (an unknown target label only with `strict_labels`)."""
    path = None
    problems = file_option_problems(body.strategy_options)
    if problems:
        raise _invalid(problems)
    if body.world is not None:
        path = world_path(settings.worlds_dir, str(body.world))
        if path is None:
            known = ", ".join(f.stem for f in world_files(settings.worlds_dir)) or "none"
            raise _invalid([("world", f"unknown world {body.world!r}; built-in worlds: {known}")])
    if checker is not None:
        found = [p for p in checker(request, path)
                 if body.strict_labels or not _unknown_label(p)]
        if found:
            raise _invalid([(p.field, p.message) for p in found])


def _unavailable(exc: StorageError) -> HTTPException:
    return HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE,
                         detail=f"{exc}; the service takes no new work until its store "
                         "accepts writes again (see /v1/health)", headers={"Retry-After": "10"})


@router.post(
    "",
    status_code=status.HTTP_202_ACCEPTED,
    responses={**_ERRORS, **TOO_LARGE, 503: {"model": Message, "description": "queue full"}},
)
def create_task(
    body: TaskCreate,
    response: Response,
    caller: WriteAccess,
    manager: ManagerDep,
    settings: SettingsDep,
    checker: TaskCheckerDep,
    idempotency_key: Annotated[str | None, Header(min_length=1, max_length=200)] = None,
) -> TaskPublic:
    """Queue a search for `target` (or the `targets`); 202 with the task (poll it or stream
    its events).

    422 when any field is wrong, checked now against the world and the knowledge base."""
    request = body.as_request()
    _check_task(body, request, settings, checker)
    digest = hashlib.sha256(json.dumps(request, sort_keys=True).encode()).hexdigest()
    try:
        submission = manager.submit(request, caller, idempotency_key, digest)
    except StorageError as exc:
        raise _unavailable(exc) from exc
    except QuotaError as exc:
        raise HTTPException(status.HTTP_429_TOO_MANY_REQUESTS, detail=str(exc),
                            headers={"Retry-After": "10"}) from exc
    except IdempotencyConflictError as exc:
        message = f"Idempotency-Key {exc} was already used with a different request body"
        raise _invalid([("idempotency-key", message)], where="header") from exc
    except BuildingWorldError as exc:
        raise _invalid([("building", str(exc))]) from exc
    except QueueFullError as exc:
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE, detail=f"task queue is full ({exc}); retry later",
            headers={"Retry-After": "5"},
        ) from exc
    if submission.replayed:
        response.headers["Idempotent-Replayed"] = "true"
    response.headers["Location"] = f"/v1/tasks/{submission.task.id}"
    return to_public(submission.task)


@router.get("", responses=_READ_ERRORS)
def list_tasks(
    store: StoreDep,
    caller: ReadAccess,
    state: TaskState | None = None,
    limit: Annotated[int, Query(ge=1, le=200)] = 50,
    offset: Annotated[int, Query(ge=0, le=1_000_000)] = 0,
) -> TasksPublic:
    """Tasks, newest first, optionally only those in one state: the caller's own (its key's
    owner), or all for an admin key (and when the service is open or reads are open)."""
    owner = None if caller.sees_all else caller.owner
    tasks, count = store.page(state, limit, offset, owner)
    return TasksPublic(data=[to_public(t, full=False) for t in tasks], count=count)


@router.get("/{task_id}", responses={**_READ_ERRORS, 404: {"model": Message}})
async def read_task(task: TaskDep) -> TaskPublic:
    """One task: its state, request, and summary (once it ended) or error."""
    return to_public(task)


@router.delete(
    "/{task_id}",
    responses={**_ERRORS, 404: {"model": Message}, 409: {"model": Message}},
)
def cancel_task(task_id: TaskId, caller: WriteAccess, manager: ManagerDep) -> TaskPublic:
    """Cancel: a queued task ends at once; a running episode is asked to stop and killed after
    a grace time, so the task returned may still say `running` for that long. A key cancels
    its own tasks (an admin key any)."""
    visible_task(manager.store, task_id, caller)
    try:
        task = manager.cancel(task_id)
    except NotCancellableError as exc:
        raise HTTPException(status.HTTP_409_CONFLICT, detail=str(exc)) from exc
    except StorageError as exc:
        raise _unavailable(exc) from exc
    if task is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no task with id {task_id}")
    return to_public(task)


class EventStream(StreamingResponse):
    media_type = "text/event-stream"


@router.get(
    "/{task_id}/events", response_class=EventStream,
    responses={
        200: {"content": {"text/event-stream": {"schema": {"type": "string"}}},
              "description": "the events, as they happen (Server-Sent Events)"},
        401: {"content": _JSON_MESSAGE, "description": "missing or wrong X-API-Key"},
        404: {"content": _JSON_MESSAGE, "description": "no such task (a JSON error body)"},
        422: {"content": _JSON_MESSAGE, "description": "a malformed Last-Event-ID"},
    },
)
async def stream_events(
    task: TaskDep,
    store: StoreDep,
    request: Request,
    last_event_id: Annotated[str | None, Header(
        alias="Last-Event-ID", max_length=20, pattern=r"^(null|[0-9]{1,19})?$",
        description="the id of the last event received (empty or `null`: from the start)",
    )] = None,
) -> EventStream:
    """The task's events as Server-Sent Events, from after `Last-Event-ID`; ends with the task,
    or with a `shutdown` event (no id) when the service stops: reconnect with Last-Event-ID.
    Errors before the stream starts (401, 404, 422) are JSON."""
    after = min(int(last_event_id), 2**62) if last_event_id and last_event_id.isdigit() else 0
    return EventStream(_events(task.id, after, store, request.app.state.draining),
                       headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})


def _json(data: Any) -> str:
    """JSON text for a client: NaN and infinities (which JSON lacks) become null."""
    try:
        return json.dumps(data, allow_nan=False)
    except ValueError:
        return json.dumps(_finite(data))


def _finite(value: Any) -> Any:
    if isinstance(value, float) and (value != value or value in (float("inf"), float("-inf"))):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


async def _events(task_id: str, after: int, store: Any, draining: Any) -> AsyncIterator[bytes]:
    """The stream's bytes; a comment line keeps an idle stream open. A client that goes away
    ends it (Starlette cancels the generator; nothing is left to fail later), and so does a
    storage error once the stream has begun (the client resumes with Last-Event-ID)."""
    quiet_since = time.monotonic()
    while True:
        if draining.is_set():
            yield format_sse_event(data_str=json.dumps(_SHUTDOWN), event="shutdown",
                                   retry=_RETRY_MS)
            return
        try:
            events = store.events_after(task_id, after)
            current = None if events else store.get(task_id)
            ended = not events and (current is None or (
                current.state.terminal and not store.events_after(task_id, after)))
        except sqlite3.Error as exc:
            log.warning("event stream of task %s ended: storage error: %s", task_id, exc)
            return
        for event in events:
            after = event.seq
            kind = str(event.data.get("type", "message")).replace("\n", " ").replace("\r", " ")
            yield format_sse_event(data_str=_json(event.data), event=kind, id=str(event.seq))
        if events:
            quiet_since = time.monotonic()
            continue
        if ended:
            return
        if time.monotonic() - quiet_since >= _KEEPALIVE_S:
            quiet_since = time.monotonic()
            yield KEEPALIVE_COMMENT
        await asyncio.sleep(_EVENT_POLL_S)


@router.get(
    "/{task_id}/trajectory.png",
    response_class=FileResponse,
    responses={200: {"content": {"image/png": {}}}, **_READ_ERRORS, 404: {"model": Message}},
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
    responses={200: {"content": {"application/octet-stream": {}}}, **_READ_ERRORS,
               404: {"model": Message}},
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


@router.get("/{task_id}/explanation", responses={**_READ_ERRORS, 404: {"model": Message}})
def read_explanation(task: TaskDep, settings: SettingsDep) -> dict[str, Any]:
    """Why the episode went as it did: the assumption ledger (every assumption its plans used,
    with its probabilities, and whether and by which observation it was confirmed or refuted),
    the reason for every replan, and for a give-up the room hypotheses tried; `avs explain`
    prints the same as text. Available once the task has ended."""
    from avs_planner.reporting.explain import FILE_NAME, ExplainError, load

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
