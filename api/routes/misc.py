"""/worlds, /strategies and /health."""

from __future__ import annotations

import sqlite3

from fastapi import APIRouter, HTTPException, status

from api.deps import ManagerDep, SettingsDep
from api.schemas import Health, Message, StrategiesPublic, StrategyPublic, WorldsPublic
from api.worlds import list_worlds
from avs_planner import __version__

router = APIRouter(tags=["service"])


@router.get("/worlds")
def read_worlds(settings: SettingsDep) -> WorldsPublic:
    """The built-in worlds a task may name."""
    worlds = list_worlds(settings.worlds_dir)
    return WorldsPublic(data=worlds, count=len(worlds))


@router.get("/strategies")
def read_strategies() -> StrategiesPublic:
    """The search strategies a task may name, with their options and defaults."""
    from avs_planner.harness.validate import strategies

    data = [StrategyPublic.model_validate(s) for s in strategies()]
    return StrategiesPublic(data=data, count=len(data))


@router.get("/health", responses={503: {"model": Message, "description": "not ready"}})
async def read_health(manager: ManagerDep, settings: SettingsDep) -> Health:
    """200 once the service is up and its workers are started; 503 if they are not. While its
    store refuses writes (e.g. the disk is full) it is still 200 with status `degraded` and
    the `reason`: reads work, new work is refused (503) until writes succeed again. No key
    is needed."""
    if not (manager.episodes.alive() and manager.jobs.alive()):
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, detail="workers not running")
    reason = manager.degraded()
    try:
        queued, running = manager.counts()
    except sqlite3.Error as exc:  # the store cannot even be read
        queued = running = 0
        reason = reason or f"storage error: {exc}"
    return Health(
        status="degraded" if reason else "ok", reason=reason, version=__version__,
        workers=manager.episodes.size, queued=queued, running=running,
        open_access=settings.is_open(),
    )
