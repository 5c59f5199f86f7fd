"""Turning a plan/check job's outcome into a response body or the right HTTP error."""

from __future__ import annotations

from collections.abc import Awaitable, Callable
from typing import Any

from fastapi import HTTPException, status

from api.limits import short
from api.manager import ClientGoneError, QueueFullError, QuotaError, StoppingError, TaskManager
from api.workers import JobOutcome

UNAVAILABLE = "JobUnavailableError"
CLIENT_CLOSED = 499  # nginx's code for "the client closed the request"; nobody receives it


def over_quota(exc: QuotaError) -> HTTPException:
    return HTTPException(status.HTTP_429_TOO_MANY_REQUESTS, detail=str(exc),
                         headers={"Retry-After": "5"})


def queue_full(exc: QueueFullError) -> HTTPException:
    return HTTPException(
        status.HTTP_503_SERVICE_UNAVAILABLE, detail=f"too many jobs waiting ({exc}); retry",
        headers={"Retry-After": "2"},
    )


async def run_job(
    manager: TaskManager, kind: str, payload: dict[str, Any],
    disconnected: Callable[[], Awaitable[bool]] | None = None,
    on_start: Callable[[], bool] = lambda: True,
) -> Any:
    """The job's return value; 503 when busy or the planner is missing, 504 on the wall clock.
    A client that disconnects has its job cancelled (the worker is freed at once)."""
    try:
        result = await manager.run_job(kind, payload, disconnected, on_start)
    except QueueFullError as exc:
        raise queue_full(exc) from exc
    except ClientGoneError as exc:
        raise HTTPException(CLIENT_CLOSED, detail="client disconnected") from exc
    except StoppingError as exc:
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE, detail="the service is stopping; retry",
            headers={"Retry-After": "5"},
        ) from exc
    if result.outcome is JobOutcome.DONE:
        return result.value
    if result.outcome is JobOutcome.CANCELLED:
        raise HTTPException(status.HTTP_409_CONFLICT, detail=f"{kind} cancelled")
    if result.outcome is JobOutcome.TIMEOUT:
        raise HTTPException(status.HTTP_504_GATEWAY_TIMEOUT,
                            detail=short(f"{kind}: {result.error}"))
    if result.error_type in (UNAVAILABLE, "MemoryError") or result.outcome is JobOutcome.SHUTDOWN:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE,
                            detail=short(f"{kind}: {result.error}"))
    raise HTTPException(
        status.HTTP_500_INTERNAL_SERVER_ERROR,
        detail=short(f"{kind} failed: {result.error_type or result.outcome.value}: "
                     f"{result.error}"),
    )


def pddl_422(errors: list[dict[str, Any]]) -> HTTPException:
    """422 whose `detail` lists each PDDL error with its body field, line and column."""
    detail = [
        {
            "type": "pddl_error",
            "loc": ["body", _field(e.get("file", ""))],
            "msg": short(str(e.get("message", ""))),
            "line": e.get("line"),
            "column": e.get("column"),
        }
        for e in errors[:50]
    ]
    return HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, detail=detail)


def _field(file: str) -> str:
    return file if file in ("domain", "problem", "options") else "body"
