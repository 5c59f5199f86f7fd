"""The planner package as the HTTP service sees it: three plain-data jobs, and what the
service reads and forgets of a building (its memory, its learned priors).

The service runs the jobs in worker processes, so inputs and outputs are JSON-able dicts and
the heavy modules are imported on first use. A part that cannot be imported (e.g. the episode
runner, `avs_planner.harness`, in a trimmed install) raises `JobUnavailableError`, never a fake
result.
"""

from __future__ import annotations

import functools
import importlib
import os
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from avs_planner.errors import AvsError, PddlError

DOMAIN_NAME = "domain"
PROBLEM_NAME = "problem"

Emit = Callable[[dict[str, Any]], None]
ShouldStop = Callable[[], bool]


class JobUnavailableError(AvsError):
    """The part of the planner a job needs is not installed or not written yet."""


def _require(module: str, what: str) -> Any:
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise JobUnavailableError(f"{what} not available yet ({module}: {exc})") from exc


def problem_name(index: int) -> str:
    """How the i-th problem text is named in diagnostics: `problem[i]`."""
    return f"{PROBLEM_NAME}[{index}]"


def check_domain(domain_text: str, problem_texts: Sequence[str] = ()) -> list[dict[str, Any]]:
    """Lint a domain and its problems: one dict per diagnostic (file, line, column, severity,
    message, code); files are named `domain` and `problem[i]`."""
    pddl = _require("avs_planner.pddl", "the PDDL linter")
    if not hasattr(pddl, "check") or not hasattr(pddl, "PddlSource"):
        raise JobUnavailableError("the PDDL linter (avs_planner.pddl.check) not available yet")
    domain = pddl.PddlSource(DOMAIN_NAME, domain_text)
    problems = [pddl.PddlSource(problem_name(i), text) for i, text in enumerate(problem_texts)]
    try:
        found = pddl.check(domain, problems)
    except PddlError as exc:  # the linter reports what it can; a hard stop is one diagnostic
        return [_error_diagnostic(exc)]
    return [_diagnostic(d) for d in found]


def _error_diagnostic(exc: PddlError) -> dict[str, Any]:
    return {
        "file": exc.file, "line": exc.line, "column": exc.column, "severity": "error",
        "message": exc.message, "code": "error",
    }


def _diagnostic(d: Any) -> dict[str, Any]:
    severity = getattr(d.severity, "value", d.severity)
    return {
        "file": d.file, "line": int(d.line), "column": int(d.column),
        "severity": str(severity), "message": d.message, "code": d.code,
    }


def plan(domain_text: str, problem_text: str, options: Mapping[str, Any] | None = None) -> dict:
    """Read and plan one problem. Returns `avs plan --json`'s dict; for bad PDDL or options
    `{"status": "invalid", "errors": [{file, line, column, message}]}`; for a problem the planner
    cannot handle `{"status": "unsupported", "message": ...}`."""
    pddl = _require("avs_planner.pddl", "the PDDL reader")
    planner = _require("avs_planner.cp.planner", "the continual planner")
    search = _require("avs_planner.cp.search", "the continual planner")
    try:
        problem = pddl.read_text(domain_text, problem_text, DOMAIN_NAME, PROBLEM_NAME)
    except PddlError as exc:
        return _invalid(exc.file, exc.line, exc.column, exc.message)
    try:
        search_options = search.SearchOptions(**dict(options or {})).check()
    except (TypeError, AvsError) as exc:  # an unknown option, or a bad value
        return _invalid("options", 1, 1, str(exc))
    try:
        result = planner.plan(problem, search_options)
    except PddlError as exc:
        return _invalid(exc.file, exc.line, exc.column, exc.message)
    except AvsError as exc:  # PlanningError: a construct the planner does not support
        return {"status": "unsupported", "message": str(exc)}
    return {**result.as_json(), "warnings": [_diagnostic(w) for w in problem.warnings]}


def _invalid(file: str, line: int, column: int, message: str) -> dict[str, Any]:
    error = {"file": file, "line": line, "column": column, "message": message}
    return {"status": "invalid", "errors": [error]}


def episode_runner_available() -> bool:
    """Whether `avs_planner.harness.run_episode` can be imported (imports it to find out)."""
    try:
        episode = importlib.import_module("avs_planner.harness")
    except ImportError:
        return False
    return callable(getattr(episode, "run_episode", None))


def run_episode(spec: Mapping[str, Any], emit: Emit, should_stop: ShouldStop) -> dict[str, Any]:
    """Run one search episode (the switching loop), streaming trace events through `emit` and
    stopping early when `should_stop()`; returns the summary (`outcome`: found/gave_up/timeout).

    `spec` holds the HTTP task body (`target`, `category`, `world` name or `world_file` YAML
    text, `robot`, `start_room`, `start`, `seed`, `time_budget_s`) plus `task_id` and
    `output_dir`, where the runner writes `trace.jsonl`, `summary.json` and `trajectory.png`
    (the service serves that picture). Events are the trace's dicts (`t`, `wall`, `type`, ...).
    """
    episode = _require("avs_planner.harness", "the episode runner (switching loop)")
    runner = getattr(episode, "run_episode", None)
    if runner is None:
        raise JobUnavailableError("the episode runner (avs_planner.harness.run_episode) not "
                                  "available yet")
    return runner(dict(spec), emit, should_stop)


# ---- buildings (the service's /v1/buildings) ----------------------------------------------

class BuildingReadError(AvsError):
    """A building's memory or the experience store cannot be read or changed; the message
    names the file."""


def building_memory(directory: str) -> dict[str, Any] | None:
    """What is remembered of a building (`episode/memory.py`) as plain data, or None when its
    directory holds no memory yet: `summary` (`BuildingMemory.summary()`) and `objects`, each
    remembered object (`kind` furniture, object or sighting) with its `label`, `position`,
    `support` label, `seen_at` (building seconds), `age_s` at the memory's clock and
    `p_in_place` then (the knowledge's mobility: P(not moved since))."""
    memory = _require("avs_planner.episode.memory", "the building memory")
    try:
        kept = memory.load(directory)
    except memory.BuildingMemoryError as exc:
        raise BuildingReadError(str(exc)) from None
    if kept is None:
        return None
    mobility = _knowledge().mobility
    objects = []
    for obj in kept.objects:
        support = obj.get("support")
        on = (kept.objects[support]["label"] if isinstance(support, int)
              and 0 <= support < len(kept.objects) else None)
        kind = "furniture" if mobility.fixed(obj["label"]) else "object"
        objects.append(_remembered(kind, obj, on, kept.clock, mobility))
    objects += [_remembered("sighting", s, s.get("support"), kept.clock, mobility)
                for s in kept.sightings]
    return {"summary": kept.summary(), "objects": objects}


def _remembered(kind: str, obj: Mapping[str, Any], support: Any, clock: float,
                mobility: Any) -> dict[str, Any]:
    seen_at = float(obj["seen_at"])
    age = max(clock - seen_at, 0.0)
    return {"kind": kind, "label": obj["label"],
            "position": [round(float(v), 3) for v in obj["position"]],
            "support": support if isinstance(support, str) else None,
            "seen_at": round(seen_at, 1), "age_s": round(age, 1),
            "p_in_place": round(mobility.still_there(obj["label"], age / 86400.0), 4)}


@functools.cache
def _knowledge() -> Any:
    """The default knowledge file (its mobility rates; the base the store's priors change)."""
    return _require("conceptual_map.knowledge.loader", "the knowledge base").load_knowledge()


def building_experience(path: str, building: str) -> dict[str, Any] | None:
    """The experience store's view of one building (`ExperienceStore.show` for its scope,
    with the all-buildings rates it has counts for), or None when the store does not exist
    or has no episode of that building."""
    if not os.path.isfile(path):
        return None
    experience = _require("conceptual_map.knowledge.experience", "the experience store")
    try:
        with experience.ExperienceStore(path, create=False) as store:
            if experience.building_scope(building) not in store.scopes():
                return None
            return store.show(_knowledge(), building)
    except experience.ExperienceError as exc:
        raise BuildingReadError(str(exc)) from None


def forget_building_experience(path: str, building: str) -> int:
    """Reset one building's scope of the experience store (what it taught the all-buildings
    scope stays); the counts removed (0 without a store)."""
    if not os.path.isfile(path):
        return 0
    experience = _require("conceptual_map.knowledge.experience", "the experience store")
    try:
        with experience.ExperienceStore(path, create=False) as store:
            return store.reset(experience.building_scope(building))
    except experience.ExperienceError as exc:
        raise BuildingReadError(str(exc)) from None
