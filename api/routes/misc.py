"""/worlds and /health."""

from __future__ import annotations

from fastapi import APIRouter

from api.deps import ManagerDep, SettingsDep
from api.schemas import Health, WorldsPublic
from api.worlds import list_worlds
from avs_planner import __version__

router = APIRouter(tags=["service"])


@router.get("/worlds")
def read_worlds(settings: SettingsDep) -> WorldsPublic:
    """The built-in worlds a task may name."""
    worlds = list_worlds(settings.worlds_dir)
    return WorldsPublic(data=worlds, count=len(worlds))


@router.get("/health")
async def read_health(manager: ManagerDep, settings: SettingsDep) -> Health:
    """200 once the service is up and its workers are started."""
    queued, running = manager.counts()
    return Health(
        status="ok", version=__version__, workers=manager.episodes.size, queued=queued,
        running=running, open_access=settings.is_open(),
    )
