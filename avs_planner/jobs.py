"""The planner package as the HTTP service sees it: three plain-data jobs, nothing else.

The service runs these in worker processes, so inputs and outputs are JSON-able dicts and the
heavy modules are imported on first use. A part that cannot be imported (e.g. the episode
runner, `avs_planner.harness`, in a trimmed install) raises `JobUnavailableError`, never a fake
result.
"""

from __future__ import annotations

import importlib
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
