"""The service's building pages as data: what `GET /v1/buildings[/{id}]` returns (pydantic
models; the task schemas are in `api/schemas.py`)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, Field

from api.schemas import TaskState


class BuildingTaskPublic(BaseModel):
    """A task run in a building (one the caller may see)."""

    id: str
    state: TaskState
    name: str | None = Field(None, description="what it looked for, as the summary names it")
    created_at: float
    finished_at: float | None = None
    tasks_before: int | None = Field(None, description="tasks its memory held when it began "
                                     "(the summary's `memory.tasks_before`)")


class RememberedObject(BaseModel):
    """An object the building's memory holds: `furniture` (a known object again at the next
    task), `object` (confirmed in the last task; a sighting to check at the next) or
    `sighting` (seen in an earlier task, not checked since)."""

    kind: Literal["furniture", "object", "sighting"]
    label: str
    position: list[float] = Field(description="x, y, z (m)")
    support: str | None = Field(None, description="the label it stood on")
    seen_at: float = Field(description="building time it was seen (simulated s)")
    age_s: float = Field(description="simulated seconds from then to the memory's clock")
    p_in_place: float = Field(description="P(not moved since) at the memory's clock, by the "
                              "knowledge's mobility rates")


class BuildingPublic(BaseModel):
    """A building the service keeps a memory of (`GET /v1/buildings`)."""

    id: str
    world: dict[str, Any] = Field(description="the world it is: `{world: NAME}`, "
                                  "`{generate: {seed, style, ...}}` or `{world_file: HASH}`")
    created_at: float = Field(description="when its first task was submitted")
    tasks: int = Field(description="tasks run (or waiting) there since it was last forgotten")
    busy: bool = Field(description="a task of it is queued or running")
    last_task: str | None = Field(None, description="the newest task's id (when the caller "
                                  "may see it)")
    last_task_at: float | None = Field(None, description="when the newest task was submitted")
    memory: dict[str, Any] | None = Field(
        None, description="what is remembered, in short (`BuildingMemory.summary()`: tasks, "
        "clock_s, saved, places, rooms, doors, objects, sightings, labels, last_seen); null "
        "before a task there ended")
    learned_priors: bool = Field(description="the experience store has counts of it")


class BuildingsPublic(BaseModel):
    data: list[BuildingPublic]
    count: int


class BuildingDetailPublic(BuildingPublic):
    """One building in full (`GET /v1/buildings/{id}`)."""

    objects: list[RememberedObject] = Field(default_factory=list,
                                            description="what its memory holds")
    experience: dict[str, Any] | None = Field(
        None, description="the experience store's view of it (`avs knowledge show "
        "--building ID`: rates with counts, file and learned values, category prior, "
        "episodes per scope); null when it has taught nothing")
    history: list[BuildingTaskPublic] = Field(
        default_factory=list, description="its tasks, newest first (at most 100; those "
        "the caller may see)")
