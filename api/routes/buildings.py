"""/buildings: the buildings the service keeps a memory of, what each remembers, and forgetting
one (`DELETE`). A task names its building with `building` (POST /v1/tasks); the memory lives
under DATA_DIR/buildings/ID/memory/, the learned priors in DATA_DIR/experience.sqlite3."""

from __future__ import annotations

import json
import logging
from typing import Annotated, Any

from fastapi import APIRouter, HTTPException, Path, status

from api.deps import ManagerDep, ReadAccess, WriteAccess
from api.manager import BuildingBusyError, TaskManager
from api.schemas import BUILDING_PATTERN, Message, TaskFormPublic
from api.schemas_buildings import (
    BuildingDetailPublic,
    BuildingPublic,
    BuildingsPublic,
    BuildingTaskPublic,
    RememberedObject,
)
from api.security import Caller
from api.store import BuildingRecord, StorageError

router = APIRouter(prefix="/buildings", tags=["buildings"])
log = logging.getLogger("avs.api.buildings")

BuildingId = Annotated[str, Path(pattern=BUILDING_PATTERN, description="a building's id")]
_READ_ERRORS: dict[int | str, dict[str, Any]] = {
    401: {"model": Message, "description": "missing or wrong X-API-Key (when the service has "
          "keys and reads are not open)"},
}
_WRITE_ERRORS: dict[int | str, dict[str, Any]] = {
    401: {"model": Message, "description": "missing or wrong X-API-Key"},
    403: {"model": Message, "description": "the key's role may not do this, or the building "
          "has tasks of other keys (only an admin key may forget it)"},
    404: {"model": Message, "description": "no such building"},
    409: {"model": Message, "description": "a task of the building is queued or running"},
    429: {"model": Message, "description": "rate limit exceeded"},
    503: {"model": Message, "description": "the store takes no writes now"},
}


def _memory(manager: TaskManager, building: str) -> dict[str, Any] | None:
    """The building's memory as plain data (`avs_planner.jobs.building_memory`); a memory
    that cannot be read is said so, not a 500."""
    from avs_planner.jobs import BuildingReadError, building_memory

    try:
        return building_memory(str(manager.memory_dir(building)))
    except BuildingReadError as exc:
        text = str(exc).replace(str(manager.settings.data_dir.resolve()), "DATA_DIR")
        return {"summary": {"error": text}, "objects": []}


def _experience(manager: TaskManager, building: str) -> dict[str, Any] | None:
    from avs_planner.jobs import BuildingReadError, building_experience

    try:
        return building_experience(str(manager.settings.experience_path), building)
    except BuildingReadError as exc:
        log.warning("building %s: %s", building, exc)
        return {"error": str(exc).replace(str(manager.settings.data_dir.resolve()),
                                          "DATA_DIR")}


def _public(manager: TaskManager, record: BuildingRecord, caller: Caller,
            memory: dict[str, Any] | None, experience: dict[str, Any] | None
            ) -> dict[str, Any]:
    tasks, count = manager.store.building_tasks(record.id, limit=1)
    last = tasks[0] if tasks else None
    return {
        "id": record.id, "world": json.loads(record.world), "created_at": record.created_at,
        "tasks": count, "busy": manager.store.building_live(record.id) > 0
        or manager.building_busy(record.id),
        "last_task": last.id if last is not None and caller.may_see(last.owner) else None,
        "last_task_at": last.created_at if last is not None else None,
        "memory": memory["summary"] if memory else None,
        "learned_priors": experience is not None and "error" not in experience,
    }


def _known(manager: TaskManager, building: str) -> BuildingRecord:
    record = manager.store.building(building)
    if record is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no building with id {building}")
    return record


@router.get("", responses=_READ_ERRORS)
def list_buildings(manager: ManagerDep, caller: ReadAccess) -> BuildingsPublic:
    """Every building the service keeps a memory of, by id: its tasks, the newest one, what
    is remembered in short, and whether it has learned priors. Buildings are the service's,
    shared by every key that names them (the robot's memory of a place); a key sees only its
    own tasks' ids."""
    data = []
    for record in manager.store.buildings():
        memory = _memory(manager, record.id)
        experience = _experience(manager, record.id)
        data.append(BuildingPublic(**_public(manager, record, caller, memory, experience)))
    return BuildingsPublic(data=data, count=len(data))


@router.get("/{building_id}", responses={**_READ_ERRORS, 404: {"model": Message}})
def read_building(building_id: BuildingId, manager: ManagerDep,
                  caller: ReadAccess) -> BuildingDetailPublic:
    """One building in full: the memory's summary and every object it remembers (furniture,
    objects, sightings: where, when, how likely still there), the experience store's view of
    it, and its tasks (newest first)."""
    record = _known(manager, building_id)
    memory = _memory(manager, building_id)
    experience = _experience(manager, building_id)
    tasks, _ = manager.store.building_tasks(building_id)
    history = []
    for task in tasks:
        if not caller.may_see(task.owner):
            continue
        form = TaskFormPublic.of_request(task.request)
        part = (task.result or {}).get("memory")
        before = part.get("tasks_before") if isinstance(part, dict) else None
        history.append(BuildingTaskPublic(
            id=task.id, state=task.state, name=form.name if form else None,
            created_at=task.created_at, finished_at=task.finished_at,
            tasks_before=before if isinstance(before, int) else None))
    return BuildingDetailPublic(
        **_public(manager, record, caller, memory, experience),
        objects=[RememberedObject.model_validate(o) for o in (memory or {}).get("objects", [])],
        experience=experience, history=history)


@router.delete("/{building_id}", status_code=status.HTTP_204_NO_CONTENT,
               responses=_WRITE_ERRORS)
def forget_building(building_id: BuildingId, manager: ManagerDep, caller: WriteAccess) -> None:
    """Forget a building: its memory files and its scope of the experience store (what it
    taught the all-buildings scope stays, as `avs knowledge reset --building` does). Its
    tasks and their results stay. 409 while a task of it is queued or running; a key that is
    not an admin's may forget only a building whose tasks are all its own (403)."""
    from avs_planner.jobs import BuildingReadError

    _known(manager, building_id)
    if not caller.sees_all:
        tasks, _ = manager.store.building_tasks(building_id, limit=1_000_000)
        if any(task.owner != caller.owner for task in tasks):
            raise HTTPException(
                status.HTTP_403_FORBIDDEN, detail=f"building {building_id} has tasks of other "
                f"keys; only an admin key may forget it")
    try:
        found = manager.forget(building_id)
    except BuildingBusyError as exc:
        raise HTTPException(status.HTTP_409_CONFLICT, detail=str(exc)) from exc
    except StorageError as exc:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, detail=str(exc),
                            headers={"Retry-After": "10"}) from exc
    except (OSError, BuildingReadError) as exc:
        text = str(exc).replace(str(manager.settings.data_dir.resolve()), "DATA_DIR")
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE,
                            detail=f"cannot forget building {building_id}: {text}",
                            headers={"Retry-After": "10"}) from exc
    if not found:
        raise HTTPException(status.HTTP_404_NOT_FOUND,
                            detail=f"no building with id {building_id}")
