"""/v1/tasks with the injected runner: life cycle, events, cancel, idempotency, errors."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app

Wait = Callable[..., dict]
Make = Callable[..., Settings]


def task_body(target: str = "quick", **extra: Any) -> dict[str, Any]:
    return {"target": target, "world": "office", **extra}


def test_submit_runs_to_success_with_summary_and_png(client: TestClient, wait_for: Wait) -> None:
    response = client.post("/v1/tasks", json=task_body("quick", seed=7))
    assert response.status_code == 202
    task = response.json()
    assert task["state"] == "queued" and response.headers["Location"] == f"/v1/tasks/{task['id']}"
    done = wait_for(client, task["id"], {"succeeded", "failed"})
    assert done["state"] == "succeeded", done
    assert done["summary"]["outcome"] == "found" and done["summary"]["seed"] == 7
    png = client.get(f"/v1/tasks/{task['id']}/trajectory.png")
    assert png.status_code == 200 and png.content.startswith(b"\x89PNG")


def test_outcomes_map_to_states(client: TestClient, wait_for: Wait) -> None:
    expected = {"hopeless": "gave_up", "boom": "failed", "other": "failed"}
    ids = {t: client.post("/v1/tasks", json=task_body(t)).json()["id"] for t in expected}
    for target, state in expected.items():
        done = wait_for(client, ids[target], {"succeeded", "failed", "gave_up"})
        assert done["state"] == state
    assert "runner exploded on purpose" in client.get(f"/v1/tasks/{ids['boom']}").json()["error"]
    assert "no known outcome" in client.get(f"/v1/tasks/{ids['other']}").json()["error"]


def test_events_stream_and_resume(client: TestClient) -> None:
    task_id = client.post("/v1/tasks", json=task_body("ticker")).json()["id"]
    with client.stream("GET", f"/v1/tasks/{task_id}/events") as stream:
        assert stream.headers["content-type"].startswith("text/event-stream")
        text = "".join(stream.iter_text())
    ids = [int(line[3:]) for line in text.splitlines() if line.startswith("id:")]
    assert ids == list(range(1, len(ids) + 1))
    assert "event: observation" in text and '"state": "succeeded"' in text.replace('":"', '": "')
    resumed = client.get(f"/v1/tasks/{task_id}/events", headers={"Last-Event-ID": str(ids[-3])})
    again = [int(ln[3:]) for ln in resumed.text.splitlines() if ln.startswith("id:")]
    assert again == ids[-2:]


def test_cancel_running_task_stops_it(client: TestClient, wait_for: Wait) -> None:
    task_id = client.post("/v1/tasks", json=task_body("slow")).json()["id"]
    wait_for(client, task_id, {"running"})
    response = client.delete(f"/v1/tasks/{task_id}")
    assert response.status_code == 200
    assert wait_for(client, task_id, {"cancelled"}, timeout=5)["state"] == "cancelled"
    assert client.delete(f"/v1/tasks/{task_id}").status_code == 409


def test_cancel_kills_a_runner_that_ignores_stop(client: TestClient, wait_for: Wait) -> None:
    task_id = client.post("/v1/tasks", json=task_body("stubborn")).json()["id"]
    wait_for(client, task_id, {"running"})
    client.delete(f"/v1/tasks/{task_id}")
    done = wait_for(client, task_id, {"cancelled"}, timeout=5)
    assert "killed" in done["error"]
    # the slot respawns its worker: the next task still runs
    next_id = client.post("/v1/tasks", json=task_body("quick")).json()["id"]
    assert wait_for(client, next_id, {"succeeded"})["state"] == "succeeded"


def test_cancel_queued_task_is_immediate(client: TestClient, wait_for: Wait) -> None:
    running = client.post("/v1/tasks", json=task_body("slow")).json()["id"]
    queued = client.post("/v1/tasks", json=task_body("quick")).json()["id"]
    assert client.delete(f"/v1/tasks/{queued}").json()["state"] == "cancelled"
    client.delete(f"/v1/tasks/{running}")
    wait_for(client, running, {"cancelled"})
    assert client.get(f"/v1/tasks/{queued}").json()["state"] == "cancelled"


def test_wall_clock_limit_kills_and_times_out(make_settings: Make, wait_for: Wait) -> None:
    with TestClient(create_app(make_settings(task_time_limit_s=0.5))) as client:
        task_id = client.post("/v1/tasks", json=task_body("stubborn")).json()["id"]
        done = wait_for(client, task_id, {"timeout", "failed"}, timeout=10)
    assert done["state"] == "timeout" and "wall-clock limit 0.5 s" in done["error"]


def test_memory_limit_fails_the_task(make_settings: Make, wait_for: Wait) -> None:
    with TestClient(create_app(make_settings(memory_limit_mb=600))) as client:
        task_id = client.post("/v1/tasks", json=task_body("hog")).json()["id"]
        done = wait_for(client, task_id, {"failed", "succeeded"})
    assert done["state"] == "failed" and "memory limit of 600 MB" in done["error"]


def test_idempotency_key_replays_and_conflicts(client: TestClient) -> None:
    headers = {"Idempotency-Key": "abc-1"}
    first = client.post("/v1/tasks", json=task_body("quick"), headers=headers)
    second = client.post("/v1/tasks", json=task_body("quick"), headers=headers)
    assert first.json()["id"] == second.json()["id"]
    assert second.headers.get("Idempotent-Replayed") == "true"
    conflict = client.post("/v1/tasks", json=task_body("quick", seed=3), headers=headers)
    assert conflict.status_code == 422
    error = conflict.json()["detail"][0]
    assert error["loc"] == ["header", "idempotency-key"] and "already used" in error["msg"]
    assert client.get("/v1/tasks").json()["count"] == 1


def test_queue_full_is_503(make_settings: Make, wait_for: Wait) -> None:
    with TestClient(create_app(make_settings(queue_size=1))) as client:
        running = client.post("/v1/tasks", json=task_body("slow")).json()["id"]
        wait_for(client, running, {"running"})
        assert client.post("/v1/tasks", json=task_body("quick")).status_code == 202
        full = client.post("/v1/tasks", json=task_body("quick"))
        assert full.status_code == 503 and "queue is full" in full.json()["detail"]
        client.delete(f"/v1/tasks/{running}")


def test_list_and_filter(client: TestClient, wait_for: Wait) -> None:
    ids = [client.post("/v1/tasks", json=task_body("quick")).json()["id"] for _ in range(2)]
    for task_id in ids:
        wait_for(client, task_id, {"succeeded"})
    page = client.get("/v1/tasks", params={"state": "succeeded", "limit": 1}).json()
    assert page["count"] == 2 and len(page["data"]) == 1
    assert client.get("/v1/tasks", params={"state": "running"}).json()["count"] == 0
    assert client.get("/v1/tasks", params={"state": "bogus"}).status_code == 422


def test_inline_world_file(client: TestClient, wait_for: Wait) -> None:
    body = {"target": "quick", "world_file": "name: tiny\nsize: [2, 2]\nrooms: []\n"}
    task_id = client.post("/v1/tasks", json=body).json()["id"]
    assert wait_for(client, task_id, {"succeeded"})["request"]["world_file"].startswith("name")


def test_events_arrive_live_and_stream_ends_with_the_task(client: TestClient) -> None:
    task_id = client.post("/v1/tasks", json=task_body("slow")).json()["id"]
    kinds: list[str] = []
    with client.stream("GET", f"/v1/tasks/{task_id}/events") as stream:
        for line in stream.iter_lines():
            if line.startswith("event:"):
                kinds.append(line.split(":", 1)[1].strip())
                if kinds[-1] == "action" and kinds.count("action") == 3:
                    client.app.state.manager.cancel(task_id)  # the episode is live: stop it
    assert kinds[:2] == ["state", "state"] and kinds[-1] == "state"
    assert client.get(f"/v1/tasks/{task_id}").json()["state"] == "cancelled"
