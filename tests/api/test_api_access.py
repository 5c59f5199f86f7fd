"""Access control for a shared service: keys with roles from a file or the
environment, reads that need a key, each key seeing its own tasks, per-key quotas."""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app
from api.security import KeyRing, KeySettingsError, Role
from avs_planner.cli import EXIT_BAD_INPUT, main

Make = Callable[..., Settings]
BODY = {"target": "slow", "world": "office"}
BOB = hashlib.sha256(b"bob-submit-key").hexdigest()  # a key may be given as its SHA-256
KEYS = f"""keys:
  - {{name: alice, role: submit, key: alice-submit-key, max_queued: 2, max_plan_jobs: 1}}
  - {{name: alice, role: read, key: alice-dashboard-key}}
  - {{name: bob, role: submit, key_sha256: {BOB}}}
  - {{name: carol, role: read, key: carol-read-key}}
  - {{name: ops, role: admin, key: ops-admin-key}}
"""


def _as(key: str) -> dict[str, str]:
    return {"X-API-Key": key}


@pytest.fixture
def keys_file(tmp_path: Path) -> Path:
    path = tmp_path / "keys.yaml"
    path.write_text(KEYS)
    path.chmod(0o600)
    return path


@pytest.fixture
def client(make_settings: Make, keys_file: Path) -> Iterator[TestClient]:
    settings = make_settings(keys_file=keys_file, queue_size=10, plan_queue_size=10)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def test_a_reader_key_cannot_submit_or_cancel(client: TestClient) -> None:
    response = client.post("/v1/tasks", json=BODY, headers=_as("carol-read-key"))
    assert response.status_code == 403
    assert "role read" in response.json()["detail"] and "submit" in response.json()["detail"]
    for path, body in (("/v1/plans", {"domain": "(x)", "problem": "(y)"}),
                       ("/v1/domains/check", {"domain": "(x)"})):
        assert client.post(path, json=body, headers=_as("carol-read-key")).status_code == 403
    task = client.post("/v1/tasks", json=BODY, headers=_as("ops-admin-key")).json()
    assert client.delete(f"/v1/tasks/{task['id']}",
                         headers=_as("carol-read-key")).status_code == 403
    assert client.get("/v1/tasks", headers=_as("carol-read-key")).status_code == 200


def test_one_key_cannot_read_anothers_task(client: TestClient) -> None:
    alices = client.post("/v1/tasks", json=BODY, headers=_as("alice-submit-key")).json()
    bobs = client.post("/v1/tasks", json=BODY, headers=_as("bob-submit-key")).json()
    path = f"/v1/tasks/{alices['id']}"
    for sub in ("", "/events", "/explanation", "/trajectory.png", "/recording.rrd"):
        response = client.get(path + sub, headers=_as("bob-submit-key"))
        assert response.status_code == 404, sub  # as if there were none: no id oracle
        assert response.headers["content-type"] == "application/json"
    assert client.delete(path, headers=_as("bob-submit-key")).status_code == 404
    assert client.get(path, headers=_as("alice-submit-key")).status_code == 200
    # keys with the same name share their tasks (alice's dashboard reads them)
    assert client.get(path, headers=_as("alice-dashboard-key")).status_code == 200
    listed = client.get("/v1/tasks", headers=_as("bob-submit-key")).json()
    assert [t["id"] for t in listed["data"]] == [bobs["id"]] and listed["count"] == 1
    assert client.get("/v1/tasks", headers=_as("carol-read-key")).json()["count"] == 0
    everything = client.get("/v1/tasks", headers=_as("ops-admin-key")).json()
    assert everything["count"] == 2  # admin sees all
    assert client.delete(path, headers=_as("ops-admin-key")).status_code == 200


def test_reads_need_a_key_unless_opened(client: TestClient, make_settings: Make,
                                        keys_file: Path) -> None:
    task = client.post("/v1/tasks", json=BODY, headers=_as("alice-submit-key")).json()
    for path in ("/v1/tasks", f"/v1/tasks/{task['id']}", f"/v1/tasks/{task['id']}/events"):
        assert client.get(path).status_code == 401
        assert client.get(path, headers=_as("wrong")).status_code == 401
    assert client.get("/v1/health").json()["open_access"] is False
    with TestClient(create_app(make_settings(keys_file=keys_file, open_reads=True))) as opened:
        mine = opened.post("/v1/tasks", json=BODY, headers=_as("alice-submit-key")).json()
        assert opened.get(f"/v1/tasks/{mine['id']}").status_code == 200
        assert opened.post("/v1/tasks", json=BODY).status_code == 401


def test_quota_of_queued_tasks_per_key(make_settings: Make, keys_file: Path) -> None:
    # one worker, busy with alice's first task: her next two wait, the one after is refused
    settings = make_settings(keys_file=keys_file, queue_size=10)
    with TestClient(create_app(settings)) as client:
        codes = []
        for _ in range(4):
            codes.append(client.post("/v1/tasks", json=BODY,
                                     headers=_as("alice-submit-key")).status_code)
            if codes[0] == 202 and len(codes) == 1:
                _wait_running(client, "alice-submit-key")
        assert codes == [202, 202, 202, 429]
        refused = client.post("/v1/tasks", json=BODY, headers=_as("alice-submit-key"))
        assert "2 queued tasks" in refused.json()["detail"] and refused.headers["Retry-After"]
        # another key has its own quota (bob: the default, 4)
        assert client.post("/v1/tasks", json=BODY,
                           headers=_as("bob-submit-key")).status_code == 202
        assert client.post("/v1/tasks", json=BODY,
                           headers=_as("ops-admin-key")).status_code == 202  # admin: none


def _wait_running(client: TestClient, key: str) -> None:
    import time

    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        tasks = client.get("/v1/tasks?state=running", headers=_as(key)).json()
        if tasks["count"]:
            return
        time.sleep(0.05)
    raise AssertionError("the first task never ran")


def test_quota_of_plan_jobs_per_key(make_settings: Make, keys_file: Path) -> None:
    from tests.api.api_fake_planner import RUNNER

    settings = make_settings(keys_file=keys_file, plan_runner=RUNNER, plan_queue_size=10)
    with TestClient(create_app(settings)) as client:
        body = {"domain": "(define (domain d))", "problem": "sleep 30"}
        first = client.post("/v1/plans?wait=false", json=body, headers=_as("alice-submit-key"))
        assert first.status_code == 202
        second = client.post("/v1/plans?wait=false", json=body, headers=_as("alice-submit-key"))
        assert second.status_code == 429 and "plan/check jobs" in second.json()["detail"]
        assert client.post("/v1/plans", json=body, headers=_as("alice-submit-key")
                           ).status_code == 429  # waiting calls count too
        # bob cannot see or cancel alice's job; alice can, and then has room again
        job = f"/v1/plans/{first.json()['id']}"
        assert client.get(job, headers=_as("bob-submit-key")).status_code == 404
        assert client.delete(job, headers=_as("bob-submit-key")).status_code == 404
        assert client.delete(job, headers=_as("alice-submit-key")).status_code == 200
        again = client.post("/v1/plans?wait=false", json=body, headers=_as("alice-submit-key"))
        assert again.status_code == 202
        client.delete(f"/v1/plans/{again.json()['id']}", headers=_as("alice-submit-key"))


def test_keys_from_the_environment_and_the_old_single_key(make_settings: Make) -> None:
    settings = make_settings(api_key="legacy-admin", api_keys="dash:read:dash-key, "
                             "ci:submit:ci-key")
    ring = KeyRing.from_settings(settings)
    assert [(k.name, k.role) for k in ring.keys] == [
        ("admin", Role.ADMIN), ("dash", Role.READ), ("ci", Role.SUBMIT)]
    assert ring.find("ci-key").max_queued == 4 and ring.find("legacy-admin").max_queued is None
    assert ring.find("nope") is None and ring.find("") is None
    with TestClient(create_app(settings)) as client:
        task = client.post("/v1/tasks", json=BODY, headers=_as("ci-key")).json()
        assert client.get(f"/v1/tasks/{task['id']}", headers=_as("legacy-admin")
                          ).status_code == 200
        assert client.get(f"/v1/tasks/{task['id']}", headers=_as("dash-key")).status_code == 404
        assert client.post("/v1/tasks", json=BODY, headers=_as("dash-key")).status_code == 403


@pytest.mark.parametrize(("api_keys", "says"), [
    ("just-a-key", "NAME:ROLE:KEY"),
    ("a:boss:k", "not read, submit or admin"),
    ("a:read:same b:submit:same", "twice"),
    ("a b:read:k", "NAME:ROLE:KEY"),
])
def test_bad_key_settings_are_refused(make_settings: Make, api_keys: str, says: str) -> None:
    with pytest.raises(KeySettingsError, match=says):
        KeyRing.from_settings(make_settings(api_keys=api_keys))


def test_bad_keys_file_is_bad_input_at_start(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "keys.yaml"
    path.write_text("keys:\n  - {name: x, role: submit}\n")
    monkeypatch.setenv("AVS_KEYS_FILE", str(path))
    assert main(["serve", "--data-dir", str(tmp_path / "data"), "--port", "0"]) == EXIT_BAD_INPUT
    assert "key_sha256" in capsys.readouterr().err
    assert not (tmp_path / "data").exists()
