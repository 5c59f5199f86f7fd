"""/worlds, /strategies and /health."""

from __future__ import annotations

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
    from avs_planner.episode.validate import strategies

    data = [StrategyPublic.model_validate(s) for s in strategies()]
    return StrategiesPublic(data=data, count=len(data))


@router.get("/health", responses={503: {"model": Message, "description": "not ready"}})
async def read_health(manager: ManagerDep, settings: SettingsDep) -> Health:
    """200 once the service is up and its workers are started; 503 if they are not."""
    if not (manager.episodes.alive() and manager.jobs.alive()):
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, detail="workers not running")
    queued, running = manager.counts()
    return Health(
        status="ok", version=__version__, workers=manager.episodes.size, queued=queued,
        running=running, open_access=settings.is_open(),
    )
