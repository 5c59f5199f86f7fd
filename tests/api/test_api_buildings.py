"""Buildings in the service: `building` on a task (its memory and learned priors, paths built
by the service only), one task at a time per building, and /v1/buildings (list, read,
forget)."""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from api.config import DEFAULT_TASK_CHECKER, Settings
from api.main import create_app
from api.store import TaskStore

Wait = Callable[..., dict]
ENDED = {"succeeded", "gave_up", "timeout", "failed", "cancelled"}


def _post(client: TestClient, **body: Any) -> Any:
    return client.post("/v1/tasks", json={"world": "office", **body})


@pytest.mark.parametrize("building", ["../etc", "..", ".", "a/b", "", "-x", "a" * 65, "a b",
                                      "x\\y", "~root", "é"])
def test_a_building_id_is_a_name_never_a_path(client: TestClient, building: str) -> None:
    response = _post(client, target="quick", building=building)
    assert response.status_code == 422, response.text
    assert [e["loc"] for e in response.json()["detail"]] == [["body", "building"]]
    assert not (client.app.state.settings.data_dir / "buildings").exists()


@pytest.mark.parametrize("key", ["memory", "experience", "output_dir", "task_id"])
def test_no_request_names_a_memory_store_or_folder(client: TestClient, key: str) -> None:
    response = _post(client, target="quick", building="b1", **{key: "/tmp/elsewhere"})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", key]


@pytest.mark.parametrize("options", [{"memory_dir": "x"}, {"experience_path": "x"},
                                     {"memory": "/tmp/m"}, {"experience": "../e.sqlite3"}])
def test_strategy_options_smuggle_no_file(client: TestClient, options: dict) -> None:
    response = _post(client, target="quick", building="b1", strategy_options=options)
    assert response.status_code == 422, response.text
    assert response.json()["detail"][0]["loc"][:2] == ["body", "strategy_options"]


def test_since_s_is_checked_and_needs_a_building(client: TestClient) -> None:
    response = _post(client, target="quick", since_s=10)
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "since_s"]
    response = _post(client, target="quick", building="b1", since_s=-1)
    assert response.json()["detail"][0]["loc"] == ["body", "since_s"]


def test_a_building_task_gets_the_service_s_paths(client: TestClient, wait_for: Wait) -> None:
    settings = client.app.state.settings
    first = _post(client, target="echo", building="office-3", since_s=86400).json()
    assert first["request"]["building"] == "office-3" and first["request"]["since_s"] == 86400
    spec = wait_for(client, first["id"], ENDED)["summary"]["spec"]
    memory = (settings.data_dir / "buildings" / "office-3" / "memory").resolve()
    assert spec["memory"] == str(memory) and memory.is_dir()
    assert spec["experience"] == str((settings.data_dir / "experience.sqlite3").resolve())
    assert spec["building"] == "office-3" and spec["since_s"] == 86400.0
    # no memory written yet: the default since_s is 0; once one is, the real seconds since
    second = _post(client, target="echo", building="office-3").json()
    assert "since_s" not in second["request"]
    assert wait_for(client, second["id"], ENDED)["summary"]["spec"]["since_s"] == 0.0
    (memory / "memory.json").write_text("{}")
    third = wait_for(client, _post(client, target="echo", building="office-3").json()["id"],
                     ENDED)
    assert 0.0 <= third["summary"]["spec"]["since_s"] < 60
    # a task without a building has none of these
    plain = wait_for(client, _post(client, target="echo").json()["id"], ENDED)
    assert not {"memory", "experience", "building", "since_s"} & set(plain["summary"]["spec"])


def test_a_building_is_always_the_same_world(client: TestClient, wait_for: Wait) -> None:
    wait_for(client, _post(client, target="quick", building="b1").json()["id"], ENDED)
    other = client.post("/v1/tasks", json={"target": "quick", "building": "b1",
                                           "generate": {"seed": 3}})
    assert other.status_code == 422
    (problem,) = other.json()["detail"]
    assert problem["loc"] == ["body", "building"] and "world 'office'" in problem["msg"]
    # a generated building's other days are the same building
    for day in (0, 2):
        response = client.post("/v1/tasks", json={
            "target": "quick", "building": "gen", "generate": {"seed": 3, "day": day,
                                                              "move": 0.5, "doors": 0.1}})
        assert response.status_code == 202, response.text
        assert response.json()["request"]["generate"] == {
            "seed": 3, "style": "office", "rooms": None, "surprise": 0.25, "day": day,
            "move": 0.5, "doors": 0.1}


@pytest.mark.parametrize(("generate", "loc"), [
    ({"seed": 3, "day": -1}, ["body", "generate", "day"]),
    ({"seed": 3, "move": 1.5}, ["body", "generate", "move"]),
    ({"seed": 3, "doors": -0.1}, ["body", "generate", "doors"]),
    ({"seed": 3, "day": 1.5}, ["body", "generate", "day"]),
])
def test_generated_days_are_checked(client: TestClient, generate: dict, loc: list) -> None:
    response = client.post("/v1/tasks", json={"target": "quick", "generate": generate})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == loc


def test_one_task_at_a_time_per_building(make_settings: Callable[..., Settings],
                                         wait_for: Wait) -> None:
    """Two workers: the second task of building a waits for the first; building b's task
    runs beside them."""
    with TestClient(create_app(make_settings(workers=2))) as client:
        ids = [_post(client, target="stint", building=b).json()["id"] for b in "aab"]
        runs = [wait_for(client, i, ENDED, timeout=30)["summary"] for i in ids]
    a1, a2, b1 = runs
    assert a2["started"] >= a1["ended"]  # one after the other
    assert b1["started"] < a1["ended"] and a1["started"] < b1["ended"]  # side by side


def test_a_cancelled_waiting_task_lets_the_next_run(make_settings: Callable[..., Settings],
                                                    wait_for: Wait) -> None:
    with TestClient(create_app(make_settings(workers=2))) as client:
        slow = _post(client, target="slow", building="a").json()["id"]
        wait_for(client, slow, {"running"})
        waiting = _post(client, target="quick", building="a").json()["id"]
        after = _post(client, target="quick", building="a").json()["id"]
        assert client.get(f"/v1/tasks/{waiting}").json()["state"] == "queued"
        assert client.delete(f"/v1/tasks/{waiting}").status_code == 200
        assert client.delete(f"/v1/tasks/{slow}").status_code == 200
        assert wait_for(client, after, ENDED)["state"] == "succeeded"
        assert client.get(f"/v1/tasks/{waiting}").json()["state"] == "cancelled"


def test_forget_a_building(client: TestClient, wait_for: Wait) -> None:
    settings = client.app.state.settings
    assert client.get("/v1/buildings").json() == {"data": [], "count": 0}
    assert client.get("/v1/buildings/nowhere").status_code == 404
    assert client.delete("/v1/buildings/nowhere").status_code == 404
    slow = _post(client, target="slow", building="b1").json()["id"]
    wait_for(client, slow, {"running"})
    listed = client.get("/v1/buildings").json()
    assert listed["count"] == 1
    (one,) = listed["data"]
    assert one["id"] == "b1" and one["busy"] and one["tasks"] == 1
    assert one["last_task"] == slow and one["memory"] is None
    assert one["world"] == {"world": "office"} and not one["learned_priors"]
    busy = client.delete("/v1/buildings/b1")
    assert busy.status_code == 409 and "queued or running" in busy.json()["detail"]
    client.delete(f"/v1/tasks/{slow}")
    wait_for(client, slow, ENDED)
    folder = settings.data_dir / "buildings" / "b1"
    (folder / "memory" / "memory.json").write_text("{}")  # what a task would have left
    detail = client.get("/v1/buildings/b1").json()
    assert [t["id"] for t in detail["history"]] == [slow] and not detail["busy"]
    assert "error" in detail["memory"]  # an unreadable memory is said so, not a 500
    assert str(settings.data_dir.resolve()) not in json.dumps(detail)
    assert client.delete("/v1/buildings/b1").status_code == 204
    assert not folder.exists()
    assert client.get("/v1/buildings/b1").status_code == 404
    assert client.get("/v1/buildings").json()["count"] == 0
    assert client.get(f"/v1/tasks/{slow}").json()["request"]["building"] == "b1"  # kept
    # the id may be used again, for another world even, and starts afresh
    again = client.post("/v1/tasks", json={"target": "quick", "building": "b1",
                                           "generate": {"seed": 1}})
    assert again.status_code == 202
    assert client.get("/v1/buildings/b1").json()["tasks"] == 1


def test_forgetting_needs_a_write_key_and_the_building_s_own_tasks(
        make_settings: Callable[..., Settings]) -> None:
    keys = "alice:submit:ka, bob:submit:kb, dash:read:kr"
    with TestClient(create_app(make_settings(api_keys=keys, api_key="kadmin"))) as client:
        alice, bob = {"X-API-Key": "ka"}, {"X-API-Key": "kb"}
        task = client.post("/v1/tasks", headers=alice, json={"target": "quick",
                                                             "world": "office",
                                                             "building": "b1"}).json()["id"]
        assert client.get(f"/v1/tasks/{task}", headers=alice).json()["request"][
            "building"] == "b1"
        assert client.get("/v1/buildings").status_code == 401
        seen = client.get("/v1/buildings/b1", headers=bob).json()
        assert seen["tasks"] == 1 and seen["last_task"] is None and seen["history"] == []
        assert client.delete("/v1/buildings/b1", headers={"X-API-Key": "kr"}).status_code == 403
        refused = client.delete("/v1/buildings/b1", headers=bob)
        assert refused.status_code == 403 and "admin" in refused.json()["detail"]
        deadline = time.monotonic() + 20
        while client.get(f"/v1/tasks/{task}", headers=alice).json()["state"] not in ENDED:
            assert time.monotonic() < deadline, "the task did not end"
            time.sleep(0.05)
        assert client.get("/v1/buildings/b1", headers=alice).json()["last_task"] == task
        assert client.delete("/v1/buildings/b1", headers=alice).status_code == 204


def test_a_store_without_buildings_opens(tmp_path: Path) -> None:
    """A store written before buildings existed: the column and table are added, its tasks
    are in no building."""
    path = tmp_path / "avs.sqlite3"
    db = sqlite3.connect(path)
    db.executescript(
        "CREATE TABLE tasks (id TEXT PRIMARY KEY, state TEXT NOT NULL, request TEXT NOT NULL, "
        "owner TEXT NOT NULL, idempotency_key TEXT, request_hash TEXT, created_at REAL NOT "
        "NULL, started_at REAL, finished_at REAL, result TEXT, error TEXT, events INTEGER NOT "
        "NULL DEFAULT 0, UNIQUE (owner, idempotency_key));"
        "INSERT INTO tasks (id, state, request, owner, created_at) VALUES "
        "('old', 'succeeded', '{\"target\": \"cup\"}', 'host:x', 1.0);")
    db.commit()
    db.close()
    store = TaskStore(path)
    old = store.get("old")
    assert old is not None and old.building is None and old.attempts == 0
    assert store.buildings() == [] and store.check() is None
    store.insert("new", {"target": "cup", "building": "b1"}, "host:x",
                 building=("b1", '{"world": "office"}'))
    assert store.get("new").building == "b1"
    assert [b.id for b in store.buildings()] == ["b1"]
    store.close()


def test_a_building_remembers_between_real_tasks(make_settings: Callable[..., Settings],
                                                 wait_for: Wait) -> None:
    """The real runner in the built-in office, two tasks in one building (11 s): the second
    starts from the first's memory; the building's list, page and forget reflect it."""
    settings = make_settings(episode_runner=Settings.model_fields["episode_runner"].default,
                             worlds_dir=Settings.model_fields["worlds_dir"].default,
                             task_checker=DEFAULT_TASK_CHECKER, record=False)
    body = {"target": "cup", "world": "office", "seed": 0, "time_budget_s": 300,
            "building": "office-1"}
    with TestClient(create_app(settings)) as client:
        first = wait_for(client, client.post("/v1/tasks", json=body).json()["id"], ENDED, 240)
        second_id = client.post("/v1/tasks", json={**body, "since_s": 600}).json()["id"]
        second = wait_for(client, second_id, ENDED, 240)
        events = client.get(f"/v1/tasks/{second_id}/events").text
        listed = client.get("/v1/buildings").json()
        detail = client.get("/v1/buildings/office-1").json()
        assert first["state"] in {"succeeded", "gave_up", "timeout"}, first["error"]
        assert second["state"] in {"succeeded", "gave_up", "timeout"}, second["error"]
        assert first["summary"]["memory"]["tasks_before"] == 0
        memory = second["summary"]["memory"]
        assert memory["tasks_before"] == 1 and memory["saved"]
        # the building's clock: the first task's time (the robot's own clock) and 600 s since
        assert 600 < memory["building_clock_s"] <= first["summary"]["sim_time_s"] + 600.1
        assert "event: memory" in events
        assert second["summary"]["experience"]["building"] == "office-1"
        (one,) = listed["data"]
        assert one["id"] == "office-1" and one["tasks"] == 2 and one["last_task"] == second_id
        assert one["memory"]["tasks"] == 2 and one["memory"]["places"] > 0
        assert one["learned_priors"]
        assert [t["id"] for t in detail["history"]] == [second_id, first["id"]]
        assert [t["tasks_before"] for t in detail["history"]] == [1, 0]
        assert detail["experience"]["scope"] == "building:office-1"
        assert detail["experience"]["episodes"]["building:office-1"] == 2
        for obj in detail["objects"]:
            assert obj["kind"] in {"furniture", "object", "sighting"}
            assert 0 <= obj["p_in_place"] <= 1 and obj["age_s"] >= 0
        folder = settings.data_dir / "buildings" / "office-1"
        assert (folder / "memory" / "memory.json").is_file()
        assert client.delete("/v1/buildings/office-1").status_code == 204
        assert not folder.exists()
        assert client.get("/v1/buildings/office-1").status_code == 404
    from conceptual_map.knowledge.experience import ExperienceStore

    with ExperienceStore(settings.data_dir / "experience.sqlite3", create=False) as store:
        assert "building:office-1" not in store.scopes() and "all" in store.scopes()
