"""The service's smaller edge cases: Last-Event-ID `null`, JSON errors on the event
stream's path (and so documented), the one-world rule in the schema, the SSE keep-alive, and
DELETE of an ended plan job."""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Callable

import pytest
from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app
from api.schemas import TaskCreate

Make = Callable[..., Settings]
UNKNOWN = "0" * 32


def _ended(client: TestClient, target: str = "quick") -> str:
    task = client.post("/v1/tasks", json={"target": target, "world": "office"}).json()
    deadline = time.monotonic() + 20
    while client.get(f"/v1/tasks/{task['id']}").json()["state"] in ("queued", "running"):
        assert time.monotonic() < deadline
        time.sleep(0.05)
    return task["id"]


def test_last_event_id_null_or_empty_is_from_the_start(client: TestClient) -> None:
    task_id = _ended(client)
    everything = client.get(f"/v1/tasks/{task_id}/events").text
    for value in ("null", ""):
        response = client.get(f"/v1/tasks/{task_id}/events", headers={"Last-Event-ID": value})
        assert response.status_code == 200 and response.text == everything
    after = client.get(f"/v1/tasks/{task_id}/events", headers={"Last-Event-ID": "2"}).text
    assert "id: 1\n" not in after and "id: 3\n" in after
    huge = client.get(f"/v1/tasks/{task_id}/events",
                      headers={"Last-Event-ID": "9" * 19})  # beyond SQLite's integers
    assert huge.status_code == 200 and huge.text == ""
    for bad in ("-1", "abc", "1e3", "9" * 25):
        assert client.get(f"/v1/tasks/{task_id}/events",
                          headers={"Last-Event-ID": bad}).status_code == 422


def test_event_stream_errors_are_json_and_documented_so(client: TestClient) -> None:
    response = client.get(f"/v1/tasks/{UNKNOWN}/events")
    assert response.status_code == 404
    assert response.headers["content-type"] == "application/json"
    responses = client.app.openapi()["paths"]["/v1/tasks/{task_id}/events"]["get"]["responses"]
    assert set(responses["200"]["content"]) == {"text/event-stream"}
    for code in ("404", "422"):
        assert set(responses[code]["content"]) == {"application/json"}, code


def test_the_schema_says_exactly_one_world() -> None:
    schema = TaskCreate.model_json_schema()
    branches = schema["oneOf"]
    assert [b["required"] for b in branches] == [["world"], ["world_file"], ["generate"]]
    import jsonschema_rs  # schemathesis's validator

    def valid(body: dict) -> bool:
        return jsonschema_rs.validator_for({"oneOf": branches}).is_valid(body)

    assert valid({"world": "office"}) and valid({"world": "office", "world_file": None})
    assert not valid({}) and not valid({"world": "office", "world_file": "a: 1"})
    assert not valid({"world": None, "generate": None})


def test_keep_alive_comments_and_a_client_leaving_log_no_error(
        client: TestClient, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    from api.routes import tasks

    monkeypatch.setattr(tasks, "_KEEPALIVE_S", 0.2)
    task = client.post("/v1/tasks", json={"target": "slow", "world": "office"}).json()
    caplog.set_level(logging.WARNING)
    pings = 0
    with client.stream("GET", f"/v1/tasks/{task['id']}/events") as stream:
        assert stream.headers["content-type"].startswith("text/event-stream")
        for line in stream.iter_lines():
            if line.startswith(": ping"):
                pings += 1
                if pings == 2:
                    break  # the client goes away mid-stream
    client.delete(f"/v1/tasks/{task['id']}")
    assert pings == 2
    time.sleep(0.3)
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR], caplog.text


def test_deleting_an_ended_plan_job_is_409_and_keeps_it(make_settings: Make) -> None:
    from tests.api.api_fake_planner import RUNNER

    with TestClient(create_app(make_settings(plan_runner=RUNNER))) as client:
        body = {"domain": "(define (domain d))", "problem": "sleep 0.01"}
        job = client.post("/v1/plans?wait=false", json=body).json()
        deadline = time.monotonic() + 20
        while client.get(f"/v1/plans/{job['id']}").json()["state"] in ("queued", "running"):
            assert time.monotonic() < deadline
            time.sleep(0.05)
        response = client.delete(f"/v1/plans/{job['id']}")
        assert response.status_code == 409 and "already ended" in response.json()["detail"]
        assert json.loads(client.get(f"/v1/plans/{job['id']}").content)["state"] == "succeeded"
