"""Bad input gets the right 4xx with a useful body: keys, rate limit, size, validation, ids."""

from __future__ import annotations

from collections.abc import Callable

from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app

Make = Callable[..., Settings]
BODY = {"target": "quick", "world": "office"}
UNKNOWN = "0" * 32


def test_api_key_required_on_every_task_call(make_settings: Make) -> None:
    with TestClient(create_app(make_settings(api_key="s3cret"))) as client:
        missing = client.post("/v1/tasks", json=BODY)
        assert missing.status_code == 401 and "X-API-Key" in missing.json()["detail"]
        wrong = client.post("/v1/tasks", json=BODY, headers={"X-API-Key": "nope"})
        assert wrong.status_code == 401
        assert client.delete(f"/v1/tasks/{UNKNOWN}").status_code == 401
        assert client.post("/v1/plans", json={"domain": "x", "problem": "y"}).status_code == 401
        ok = client.post("/v1/tasks", json=BODY, headers={"X-API-Key": "s3cret"})
        assert ok.status_code == 202
        task = f"/v1/tasks/{ok.json()['id']}"
        for path in (task, f"{task}/events", "/v1/tasks", f"/v1/plans/{UNKNOWN}"):
            assert client.get(path).status_code == 401, path  # reads need the key too
        assert client.get(task, headers={"X-API-Key": "s3cret"}).status_code == 200
        for path in ("/v1/health", "/v1/worlds", "/v1/strategies"):  # no one's data
            assert client.get(path).status_code == 200, path
        assert client.get("/v1/health").json()["open_access"] is False


def test_open_reads_setting_opens_gets_only(make_settings: Make) -> None:
    with TestClient(create_app(make_settings(api_key="s3cret", open_reads=True))) as client:
        ok = client.post("/v1/tasks", json=BODY, headers={"X-API-Key": "s3cret"})
        assert client.get(f"/v1/tasks/{ok.json()['id']}").status_code == 200
        assert client.get("/v1/tasks").json()["count"] == 1
        assert client.post("/v1/tasks", json=BODY).status_code == 401


def test_rate_limit_per_key(make_settings: Make) -> None:
    settings = make_settings(rate_limit_per_minute=1, rate_limit_burst=2, queue_size=10)
    with TestClient(create_app(settings)) as client:
        codes = [client.delete(f"/v1/tasks/{UNKNOWN}").status_code for _ in range(3)]
        assert codes == [404, 404, 429]
        limited = client.delete(f"/v1/tasks/{UNKNOWN}")
        assert "rate limit" in limited.json()["detail"] and int(limited.headers["Retry-After"]) > 0
        assert client.get("/v1/tasks").status_code == 200  # reads are not limited


def test_huge_body_is_413(make_settings: Make) -> None:
    with TestClient(create_app(make_settings(max_body_bytes=4096))) as client:
        response = client.post("/v1/tasks", json={**BODY, "world_file": "x" * 10_000})
    assert response.status_code == 413
    assert "4096 bytes" in response.json()["detail"]


def test_validation_errors_name_the_field(client: TestClient) -> None:
    cases = [
        ({"world": "office"}, ["body", "target"]),
        ({**BODY, "seed": -1}, ["body", "seed"]),
        ({**BODY, "robot": "r2d2"}, ["body", "robot"]),
        ({**BODY, "start": [1, 2]}, ["body", "start"]),
        ({**BODY, "time_budget_s": 0}, ["body", "time_budget_s"]),
        ({**BODY, "colour": "red"}, ["body", "colour"]),
        ({"target": "quick"}, ["body"]),
        ({**BODY, "world": "atlantis"}, ["body", "world"]),
        ({"target": "quick", "world_file": "a: [1,"}, ["body", "world_file"]),
        ({"target": "quick", "world_file": "- just a list"}, ["body", "world_file"]),
    ]
    for body, loc in cases:
        response = client.post("/v1/tasks", json=body)
        assert response.status_code == 422, body
        detail = response.json()["detail"]
        assert any(d["loc"][: len(loc)] == loc for d in detail), (body, detail)
    unknown = client.post("/v1/tasks", json={**BODY, "world": "atlantis"}).json()["detail"][0]
    assert "built-in worlds: office" in unknown["msg"]
    yaml_error = client.post("/v1/tasks", json={"target": "x", "world_file": "a: [1,"}).json()
    assert "line" in yaml_error["detail"][0]["msg"]


def test_malformed_json_is_422(client: TestClient) -> None:
    response = client.post(
        "/v1/tasks", content=b"{not json", headers={"Content-Type": "application/json"}
    )
    assert response.status_code == 422


def test_unknown_ids_are_404(client: TestClient) -> None:
    for path in ("", "/events", "/trajectory.png"):
        response = client.get(f"/v1/tasks/{UNKNOWN}{path}")
        assert response.status_code == 404 and UNKNOWN in response.json()["detail"]
    assert client.delete(f"/v1/tasks/{UNKNOWN}").status_code == 404
    assert client.get("/v1/nowhere").status_code == 404


def test_bad_last_event_id_is_422(client: TestClient) -> None:
    task_id = client.post("/v1/tasks", json=BODY).json()["id"]
    response = client.get(f"/v1/tasks/{task_id}/events", headers={"Last-Event-ID": "abc"})
    assert response.status_code == 422


def test_trajectory_404_until_drawn(client: TestClient) -> None:
    task_id = client.post("/v1/tasks", json={**BODY, "target": "slow"}).json()["id"]
    response = client.get(f"/v1/tasks/{task_id}/trajectory.png")
    assert response.status_code == 404 and "no trajectory picture yet" in response.json()["detail"]
    client.delete(f"/v1/tasks/{task_id}")


def test_health_and_worlds_and_docs(client: TestClient) -> None:
    health = client.get("/v1/health")
    assert health.status_code == 200 and health.json()["status"] == "ok"
    assert health.json()["open_access"] is True
    worlds = client.get("/v1/worlds").json()
    assert worlds["count"] == 1 and worlds["data"][0] == {"name": "office", "rooms": ["kitchen"]}
    assert client.get("/docs").status_code == 200
    assert "/v1/tasks/{task_id}/events" in client.get("/openapi.json").json()["paths"]


def test_huge_streamed_body_is_413(make_settings: Make) -> None:
    def chunks():
        for _ in range(10):
            yield b"x" * 1024

    with TestClient(create_app(make_settings(max_body_bytes=4096))) as client:
        response = client.post(
            "/v1/plans", content=chunks(), headers={"Content-Type": "application/json"}
        )
    assert response.status_code == 413


def test_health_is_503_when_workers_are_gone(client: TestClient) -> None:
    client.app.state.manager.episodes.stop()
    response = client.get("/v1/health")
    assert response.status_code == 503 and "workers" in response.json()["detail"]


def test_lists_elide_inline_world_files(client: TestClient) -> None:
    world = "name: tiny\nsize: [2, 2]\nrooms: []\n"
    task_id = client.post("/v1/tasks", json={"target": "slow", "world_file": world}).json()["id"]
    listed = client.get("/v1/tasks").json()["data"][0]["request"]["world_file"]
    assert listed == f"<inline, {len(world)} chars>"
    assert client.get(f"/v1/tasks/{task_id}").json()["request"]["world_file"] == world
    client.delete(f"/v1/tasks/{task_id}")


def test_key_guessing_is_rate_limited(make_settings: Make) -> None:
    settings = make_settings(api_key="s3cret", rate_limit_per_minute=1, rate_limit_burst=2)
    with TestClient(create_app(settings)) as client:
        guesses = [
            client.delete(f"/v1/tasks/{UNKNOWN}", headers={"X-API-Key": f"guess{i}"}).status_code
            for i in range(3)
        ]
        assert guesses == [401, 401, 429]
        right = client.delete(f"/v1/tasks/{UNKNOWN}", headers={"X-API-Key": "s3cret"})
        assert right.status_code == 404  # the key holder has a bucket of its own
