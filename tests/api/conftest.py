"""Fixtures for the API tests: an app on a temporary data dir with the injected fake runner."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app

FAKE_RUNNER = f"{Path(__file__).with_name('api_fake_runner.py').resolve()}:run"
OFFICE = (
    "name: office\nsize: [12.0, 8.0]\n"
    "rooms:\n  - {name: kitchen, category: kitchen, rect: [0, 4, 4, 8]}\n"
)


@pytest.fixture
def make_settings(tmp_path: Path) -> Callable[..., Settings]:
    worlds = tmp_path / "worlds"
    worlds.mkdir(exist_ok=True)
    (worlds / "office.yaml").write_text(OFFICE)

    def make(**overrides: Any) -> Settings:
        values: dict[str, Any] = {
            "data_dir": tmp_path / "data", "worlds_dir": worlds, "workers": 1,
            "plan_workers": 1, "episode_runner": FAKE_RUNNER, "cancel_grace_s": 0.5,
            "api_key": None, "memory_limit_mb": 0,
            "preload_planner": False, "warm_workers": False, "task_checker": None,
        }
        values.update(overrides)
        return Settings(**values)

    return make


@pytest.fixture
def client(make_settings: Callable[..., Settings]) -> Iterator[TestClient]:
    with TestClient(create_app(make_settings())) as test_client:
        yield test_client


def _wait_for(client: TestClient, task_id: str, states: set[str], timeout: float = 20) -> dict:
    """Poll a task until it reaches one of `states` (fails the test after `timeout`)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        task = client.get(f"/v1/tasks/{task_id}").json()
        if task["state"] in states:
            return task
        time.sleep(0.05)
    raise AssertionError(f"task {task_id} still {task['state']} after {timeout} s")


@pytest.fixture
def wait_for() -> Callable[..., dict]:
    """`wait_for(client, task_id, states, timeout=20)` -> the task once in one of `states`."""
    return _wait_for
