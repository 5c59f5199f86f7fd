"""Checking a task before it is queued: each problem names the field that is wrong.

The HTTP service calls `check_task` at submission, so a task that could never run (unknown
label, category, start room, a start pose in a wall or outside the map, a bad strategy option)
is refused at once instead of taking a queue slot and a worker. A target label the knowledge
does not list is refused unless the task sets `strict_labels: false` (the episode then searches
for it with the knowledge's uninformed prior; `EpisodeSpec.strict_labels` defaults to false).
This is wiring, so it may read the world file through `sim`; it never builds a physics world.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache, lru_cache
from pathlib import Path
from typing import Any

from matplotlib.path import Path as MplPath

from avs_planner.episode.errors import EpisodeError
from avs_planner.harness.sim_robot import check_categories, free_spot, generated_spec
from avs_planner.harness.tasks import TaskForm, TaskFormError
from avs_planner.strategies import get_strategy, strategy_names
from conceptual_map.knowledge.loader import load_knowledge
from conceptual_map.knowledge.model import Knowledge
from sim.errors import SimError
from sim.robot_models import ROBOT_MODELS
from sim.world_file import load_world_spec, load_world_text
from sim.world_spec import WorldSpec


@dataclass(frozen=True)
class FieldProblem:
    """`field` is the task's key (e.g. `start`, `strategy_options`); `message` says why."""

    field: str
    message: str


def check_task(task: Mapping[str, Any], world_path: Path | None = None) -> list[FieldProblem]:
    """Everything wrong with `task` (the episode spec keys), or []; `world_path` is the file of
    the built-in world `task["world"]` names (ignored when `world_file` is given)."""
    problems = _check_strategy(task) + _check_labels(task, _knowledge()) + _check_qsr(task)
    field = next((key for key in ("world_file", "generate") if task.get(key) is not None),
                 "world")
    try:
        spec = _world(task, world_path)
        check_categories(spec, _knowledge().categories)
    except (SimError, EpisodeError, OSError) as exc:
        return [*problems, FieldProblem(field, str(exc))]
    return problems + _check_start(task, spec)


def strategies() -> list[dict[str, Any]]:
    """The strategies a task may name: name, summary, options with their defaults."""
    found = [get_strategy(name) for name in strategy_names()]
    return [{"name": s.name, "summary": s.summary, "options": dict(s.options)} for s in found]


@cache
def _knowledge() -> Knowledge:
    return load_knowledge()


def _check_strategy(task: Mapping[str, Any]) -> list[FieldProblem]:
    try:
        strategy = get_strategy(str(task.get("strategy") or "switching"))
    except EpisodeError as exc:
        return [FieldProblem("strategy", str(exc))]
    try:
        strategy.check_options(task.get("strategy_options") or {})
    except EpisodeError as exc:
        return [FieldProblem("strategy_options", str(exc))]
    return []


def _check_labels(task: Mapping[str, Any], knowledge: Knowledge) -> list[FieldProblem]:
    """The task's form (`target` or `targets`, `mode`, `count`, `stop_below`: `TaskForm`)
    and every target label, then the category, against the knowledge."""
    problems = []
    # a task that does not say (the service's schema has no `strict_labels` yet) is checked
    # strictly, as before; `strict_labels: false` accepts a label the knowledge does not
    # list (the episode searches for it with the uninformed prior, `Knowledge.with_label`)
    strict = task.get("strict_labels", True)
    if not isinstance(strict, bool):
        problems.append(FieldProblem("strict_labels", f"must be true or false, got {strict!r}"))
    try:
        form = TaskForm.from_spec(task)
    except TaskFormError as exc:
        problems.append(FieldProblem(exc.key, str(exc).removeprefix("episode spec: ")))
    else:
        field = "targets" if task.get("targets") is not None else "target"
        for label in form.targets:
            if strict is not False and knowledge.spelled(label) not in knowledge.labels:
                problems.append(FieldProblem(field, f"unknown object label {label!r}; the "
                                             f"knowledge base knows {_listed(knowledge.labels)}"))
        try:
            form.spelled(knowledge.spelled)  # "Cup" and "cup" are one label twice
        except EpisodeError as exc:
            problems.append(FieldProblem(field, str(exc).removeprefix("episode spec: ")))
    category = task.get("category")
    if category is not None and (not isinstance(category, str)
                                 or knowledge.spelled(category) not in knowledge.categories):
        problems.append(FieldProblem("category", f"unknown room category {category!r}; the "
                                     f"knowledge base knows {_listed(knowledge.categories)}"))
    return problems


def _check_qsr(task: Mapping[str, Any]) -> list[FieldProblem]:
    """The task's QSR descriptions, checked as the episode runner reads them (each message
    names the entry, e.g. `qsr: descriptions[1].of: unknown landmark label 'sofa' ...`)."""
    if task.get("qsr") is None:
        return []
    from avs_planner.harness.runner import qsr_descriptions

    try:
        qsr_descriptions(task["qsr"], source="qsr")
    except EpisodeError as exc:
        return [FieldProblem("qsr", str(exc).removeprefix("episode spec: "))]
    return []


def _listed(names: Sequence[str] | frozenset[str]) -> str:
    return ", ".join(sorted(names))


def _world(task: Mapping[str, Any], world_path: Path | None) -> WorldSpec:
    text = task.get("world_file")
    if text is not None:
        return load_world_text(str(text), "world_file")
    generate = task.get("generate")
    if generate is not None:
        return _generated(tuple(sorted((k, v) for k, v in dict(generate).items()
                                       if v is not None)))
    if world_path is None:
        raise EpisodeError(f"unknown world {task.get('world')!r}")
    return _world_file(str(world_path), world_path.stat().st_mtime_ns)


@lru_cache(maxsize=32)
def _generated(arguments: tuple[tuple[str, Any], ...]) -> WorldSpec:
    """The generated building (its robot and start as generated; the task's are checked
    after). The message drops the runner's `generate: ` prefix: the field names it."""
    try:
        return generated_spec(dict(arguments))
    except EpisodeError as exc:
        raise EpisodeError(str(exc).removeprefix("generate: ")) from exc


@lru_cache(maxsize=32)
def _world_file(path: str, _mtime_ns: int) -> WorldSpec:
    return load_world_spec(Path(path))


def _check_start(task: Mapping[str, Any], spec: WorldSpec) -> list[FieldProblem]:
    model = str(task.get("robot") or spec.robot.model)
    room_name = task.get("start_room")
    if room_name is not None:
        room = spec.room(str(room_name))
        if room is None:
            return [FieldProblem("start_room", f"no room {room_name!r} in world {spec.name!r} "
                                 f"(rooms: {_listed([r.name for r in spec.rooms])})")]
        try:
            free_spot(spec, room, model)
        except EpisodeError as exc:
            return [FieldProblem("start_room", str(exc))]
    start = task.get("start")
    if start is not None:
        problem = start_problem(spec, start, model)
        if problem:
            return [FieldProblem("start", problem)]
    return []


def start_problem(spec: WorldSpec, start: Sequence[Any], model: str) -> str | None:
    """Why the robot `model` cannot start at `start` (x, y, yaw) in `spec`, or None."""
    try:
        x, y, yaw = (float(v) for v in start)
    except (TypeError, ValueError):
        return f"start pose must be [x, y, yaw], got {start!r}"
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        return f"start pose must be 3 finite numbers, got {start!r}"
    if spec.room_at(x, y) is None:
        return f"({x:g}, {y:g}) is outside every room of world {spec.name!r}"
    radius = ROBOT_MODELS[model].footprint_radius if model in ROBOT_MODELS else 0.5
    for item in spec.furniture:
        if MplPath(item.footprint()).contains_point((x, y), radius=2 * radius) or MplPath(
                item.footprint()).contains_point((x, y), radius=-2 * radius):
            return f"({x:g}, {y:g}) is not free: the robot would stand in {item.name!r}"
    return None
