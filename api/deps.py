"""Dependencies shared by the routes, as `Annotated` aliases (the FastAPI template's idiom)."""

from __future__ import annotations

import math
from typing import Annotated

from fastapi import Depends, Header, HTTPException, Path, Request, status

from api.config import Settings
from api.manager import TaskChecker, TaskManager
from api.security import Caller, KeyRing, Role, owner_of
from api.store import TaskRecord, TaskStore

NO_KEY = "missing or wrong X-API-Key header (this service requires an API key)"


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
ApiKeyHeader = Annotated[str | None, Header(
    max_length=512, description="an API key (required when the service has keys; reads too, "
    "unless AVS_OPEN_READS)")]


def _caller(request: Request, settings: Settings, given: str | None, need: Role) -> Caller:
    """The caller, or 401 (no or unknown key) / 403 (the key's role is below `need`).

    Failed key checks count against the caller's host, so guessing keys is rate limited."""
    host = request.client.host if request.client else "unknown"
    keys: KeyRing = request.app.state.keys
    if keys.open:  # no keys: everyone may do everything, tasks are the host's (as before)
        return Caller(owner_of(None, host), Role.ADMIN, "anonymous", sees_all=True)
    if not given and need is Role.READ and keys.open_reads:
        return Caller("anonymous", Role.READ, "anonymous", sees_all=True)
    key = keys.find(given)
    if key is None:
        _limit(request.app.state.rate_limiter.acquire(owner_of(None, host)), settings)
        raise HTTPException(status.HTTP_401_UNAUTHORIZED, detail=NO_KEY,
                            headers={"WWW-Authenticate": "X-API-Key"})
    if key.role < need:
        raise HTTPException(
            status.HTTP_403_FORBIDDEN,
            detail=f"key {key.name!r} has role {key.role.label}; this call needs "
            f"{need.label} or above")
    return key.caller(keys.open_reads)


async def require_read_access(request: Request, settings: SettingsDep,
                              x_api_key: ApiKeyHeader = None) -> Caller:
    """A key of any role (none needed when the service is open or AVS_OPEN_READS is set)."""
    return _caller(request, settings, x_api_key, Role.READ)


async def require_write_access(request: Request, settings: SettingsDep,
                               x_api_key: ApiKeyHeader = None) -> Caller:
    """A submit or admin key (401/403), within the caller's rate limit (429)."""
    caller = _caller(request, settings, x_api_key, Role.SUBMIT)
    _limit(request.app.state.rate_limiter.acquire(caller.owner), settings)
    return caller


def _limit(wait: float, settings: Settings) -> None:
    if wait > 0:
        raise HTTPException(
            status.HTTP_429_TOO_MANY_REQUESTS,
            detail=f"rate limit of {settings.rate_limit_per_minute:g} calls/minute exceeded; "
            f"retry in {wait:.1f} s",
            headers={"Retry-After": str(math.ceil(wait))},
        )


ReadAccess = Annotated[Caller, Depends(require_read_access)]
WriteAccess = Annotated[Caller, Depends(require_write_access)]

TaskId = Annotated[str, Path(max_length=64, description="a task id")]


def visible_task(store: TaskStore, task_id: str, caller: Caller) -> TaskRecord:
    """The task, or 404 when there is none or it belongs to another key (the same answer, so
    ids of others' tasks cannot be probed)."""
    task = store.get(task_id)
    if task is None or not caller.may_see(task.owner):
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no task with id {task_id}")
    return task


async def get_task(task_id: TaskId, store: StoreDep, caller: ReadAccess) -> TaskRecord:
    return visible_task(store, task_id, caller)


TaskDep = Annotated[TaskRecord, Depends(get_task)]
