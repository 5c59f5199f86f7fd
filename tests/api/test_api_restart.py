"""Nothing is lost or left running forever across a restart (fail or requeue policy)."""

from __future__ import annotations

from collections.abc import Callable

from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app

Make = Callable[..., Settings]
Wait = Callable[..., dict]


def _start_slow_task(client: TestClient, wait_for: Wait) -> str:
    task_id = client.post("/v1/tasks", json={"target": "slow", "world": "office"}).json()["id"]
    wait_for(client, task_id, {"running"})
    return task_id


def test_restart_marks_interrupted_task_failed(make_settings: Make, wait_for: Wait) -> None:
    with TestClient(create_app(make_settings())) as client:
        task_id = _start_slow_task(client, wait_for)
        queued = client.post("/v1/tasks", json={"target": "quick", "world": "office"}).json()["id"]
    with TestClient(create_app(make_settings())) as client:
        task = client.get(f"/v1/tasks/{task_id}").json()
        assert task["state"] == "failed" and "interrupted" in task["error"]
        assert wait_for(client, queued, {"succeeded"})["state"] == "succeeded"
        events = client.get(f"/v1/tasks/{task_id}/events").text
        assert '"state":"failed"' in events.replace(" ", "")


def test_restart_requeues_when_configured(make_settings: Make, wait_for: Wait) -> None:
    with TestClient(create_app(make_settings())) as client:
        task_id = _start_slow_task(client, wait_for)
    settings = make_settings(on_restart="requeue")
    with TestClient(create_app(settings)) as client:
        wait_for(client, task_id, {"running"})
        client.delete(f"/v1/tasks/{task_id}")
        assert wait_for(client, task_id, {"cancelled"})["state"] == "cancelled"
