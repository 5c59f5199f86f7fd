"""`avs_planner.jobs`, the only planner code the service calls: plain data in and out."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from api.config import DEFAULT_EPISODE_RUNNER, Settings
from api.main import create_app
from api.worker_process import resolve
from avs_planner import jobs

TRIMMED_RUNNER = """
import sys

from avs_planner import jobs


def run(spec, emit, should_stop):
    sys.modules["avs_planner.harness"] = None  # a trimmed install: the package is missing
    return jobs.run_episode(spec, emit, should_stop)
"""


def test_run_episode_says_the_runner_is_missing(monkeypatch: pytest.MonkeyPatch) -> None:
    assert jobs.episode_runner_available()
    monkeypatch.setitem(sys.modules, "avs_planner.harness", None)
    assert not jobs.episode_runner_available()
    with pytest.raises(jobs.JobUnavailableError, match="episode runner .* not available yet"):
        jobs.run_episode({"target": "cup"}, lambda event: None, lambda: False)


def test_task_fails_clearly_without_the_runner(
    make_settings: Callable[..., Settings], wait_for: Callable[..., dict], tmp_path: Path
) -> None:
    runner = tmp_path / "trimmed_runner.py"
    runner.write_text(TRIMMED_RUNNER, encoding="utf-8")
    settings = make_settings(episode_runner=f"{runner}:run")
    with TestClient(create_app(settings)) as client:
        task_id = client.post("/v1/tasks", json={"target": "cup", "world": "office"}).json()["id"]
        done = wait_for(client, task_id, {"failed", "succeeded"})
    assert done["state"] == "failed" and "not available yet" in done["error"]


def test_plan_reports_bad_options_as_invalid() -> None:
    domain = "(define (domain d) (:predicates (p)) (:action a :parameters () :effect (p)))"
    problem = "(define (problem q) (:domain d) (:init) (:goal (p)))"
    bad = jobs.plan(domain, problem, {"weight": 0.5})
    assert bad["status"] == "invalid" and bad["errors"][0]["file"] == "options"
    unknown = jobs.plan(domain, problem, {"colour": 1})
    assert unknown["status"] == "invalid" and unknown["errors"][0]["file"] == "options"
    assert jobs.plan(domain, problem, {})["plan"] == ["(a)"]


def test_resolve_runner_specs() -> None:
    assert resolve("avs_planner.jobs:plan") is jobs.plan
    for spec in ("no-colon", ":x", "avs_planner.jobs:"):
        with pytest.raises(ValueError, match="not 'module:function'"):
            resolve(spec)


@pytest.mark.slow  # a real PyBullet episode: tens of seconds
def test_real_episode_end_to_end(
    make_settings: Callable[..., Settings], wait_for: Callable[..., dict]
) -> None:
    settings = make_settings(episode_runner=DEFAULT_EPISODE_RUNNER, worlds_dir=None)
    body = {"target": "cerealbox", "world": "office", "seed": 1, "time_budget_s": 30}
    with TestClient(create_app(settings)) as client:
        task_id = client.post("/v1/tasks", json=body).json()["id"]
        done = wait_for(client, task_id, {"succeeded", "gave_up", "timeout", "failed"}, 300)
        events = client.get(f"/v1/tasks/{task_id}/events").text
        picture = client.get(f"/v1/tasks/{task_id}/trajectory.png")
    assert done["state"] != "failed", done["error"]
    assert done["summary"]["target"] == "cerealbox"
    assert "event: plan" in events and "event: done" in events
    assert picture.status_code == 200 and picture.content.startswith(b"\x89PNG")
