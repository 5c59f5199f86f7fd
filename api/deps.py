"""Dependencies shared by the routes, as `Annotated` aliases (the FastAPI template's idiom)."""

from __future__ import annotations

import math
from typing import Annotated

from fastapi import Depends, Header, HTTPException, Path, Request, status

from api.config import Settings
from api.manager import TaskChecker, TaskManager
from api.security import RateLimiter, key_matches, owner_of
from api.store import TaskRecord, TaskStore


async def get_settings(request: Request) -> Settings:
    return request.app.state.settings


async def get_manager(request: Request) -> TaskManager:
    return request.app.state.manager


async def get_store(request: Request) -> TaskStore:
    return request.app.state.manager.store


async def get_task_checker(request: Request) -> TaskChecker | None:
    return request.app.state.manager.task_checker


SettingsDep = Annotated[Settings, Depends(get_settings)]
TaskCheckerDep = Annotated[TaskChecker | None, Depends(get_task_checker)]
ManagerDep = Annotated[TaskManager, Depends(get_manager)]
StoreDep = Annotated[TaskStore, Depends(get_store)]


async def require_write_access(
    request: Request,
    settings: SettingsDep,
    x_api_key: Annotated[str | None, Header(description="required when AVS_API_KEY is set")] = None,
) -> str:
    """Check the API key (401) and the caller's rate limit (429); returns the caller's owner id.

    Failed key checks count against the caller's host, so guessing keys is rate limited too."""
    host = request.client.host if request.client else "unknown"
    limiter: RateLimiter = request.app.state.rate_limiter
    if settings.api_key and not key_matches(x_api_key, settings.api_key):
        _limit(limiter.acquire(owner_of(None, host)), settings)
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED,
            detail="missing or wrong X-API-Key header (this service requires an API key)",
            headers={"WWW-Authenticate": "X-API-Key"},
        )
    owner = owner_of(x_api_key if settings.api_key else None, host)
    _limit(limiter.acquire(owner), settings)
    return owner


def _limit(wait: float, settings: Settings) -> None:
    if wait > 0:
        raise HTTPException(
            status.HTTP_429_TOO_MANY_REQUESTS,
            detail=f"rate limit of {settings.rate_limit_per_minute:g} calls/minute exceeded; "
            f"retry in {wait:.1f} s",
            headers={"Retry-After": str(math.ceil(wait))},
        )


WriteAccess = Annotated[str, Depends(require_write_access)]

TaskId = Annotated[str, Path(max_length=64, description="a task id")]


async def get_task(task_id: TaskId, store: StoreDep) -> TaskRecord:
    task = store.get(task_id)
    if task is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no task with id {task_id}")
    return task


TaskDep = Annotated[TaskRecord, Depends(get_task)]
