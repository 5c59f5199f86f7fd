"""Faults recover without a restart: a store that fails writes (disk full)
fails the affected task with the reason, keeps the workers, turns health to degraded and back,
and runs the waiting tasks then; no error is plain text; a damaged store at start-up is a
documented exit code with a one-line message."""

from __future__ import annotations

import sqlite3
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app
from api.store import StorageError, TaskStore
from avs_planner.cli import main
from avs_planner.cli.serve import EXIT_STORE_CORRUPT

Make = Callable[..., Settings]
FULL = "database or disk is full"


class _FullDisk:
    """Stands between the store and its SQLite connection: while `full`, every statement that
    writes fails as SQLite fails on a full disk (reads work, as they do then)."""

    def __init__(self, conn: sqlite3.Connection):
        self.conn = conn
        self.full = False

    def execute(self, sql: str, *args: Any) -> Any:
        if self.full and sql.lstrip().upper().startswith(("INSERT", "UPDATE", "DELETE")):
            raise sqlite3.OperationalError(FULL)
        return self.conn.execute(sql, *args)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.conn, name)


@contextmanager
def full_disk(client: TestClient) -> Iterator[_FullDisk]:
    store: TaskStore = client.app.state.manager.store
    with store._lock:
        disk = _FullDisk(store._conn)
        store._conn = disk  # type: ignore[assignment]
    try:
        yield disk
    finally:
        with store._lock:
            store._conn = disk.conn


def _until(check: Callable[[], Any], timeout: float = 20, what: str = "") -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = check()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"not within {timeout} s: {what}")


def _state(client: TestClient, task_id: str) -> str:
    return client.get(f"/v1/tasks/{task_id}").json()["state"]


def test_a_full_disk_fails_the_task_degrades_and_recovers(make_settings: Make) -> None:
    with TestClient(create_app(make_settings()), raise_server_exceptions=False) as client:
        dripping = client.post("/v1/tasks", json={"target": "drip", "world": "office"}).json()
        _until(lambda: client.get(f"/v1/tasks/{dripping['id']}").json()["events"] > 5,
               what="the episode's events")
        waiting = client.post("/v1/tasks", json={"target": "quick", "world": "office"}).json()
        with full_disk(client) as disk:
            disk.full = True
            health = _until(lambda: (h := client.get("/v1/health").json())["status"] ==
                            "degraded" and h, what="health degraded")
            assert FULL in health["reason"]
            refused = client.post("/v1/tasks", json={"target": "quick", "world": "office"})
            assert refused.status_code == 503 and FULL in refused.json()["detail"]
            assert refused.headers["content-type"] == "application/json"
            assert int(refused.headers["Retry-After"]) > 0
            time.sleep(1.0)  # the episode was stopped; the queued task could not start
            assert _state(client, waiting["id"]) == "queued"
            assert client.get("/v1/health").status_code == 200  # the workers are alive
            assert client.app.state.manager.episodes.alive()
            disk.full = False  # space is back
            freed = time.monotonic()
            _until(lambda: _state(client, waiting["id"]) == "succeeded", timeout=10,
                   what="the waiting task ran")
            recovered_s = time.monotonic() - freed
        failed = client.get(f"/v1/tasks/{dripping['id']}").json()
        assert failed["state"] == "failed"
        assert FULL in failed["error"] and "could not be recorded" in failed["error"]
        assert client.get("/v1/health").json() == {**client.get("/v1/health").json(),
                                                   "status": "ok", "reason": None}
        assert recovered_s < 10
        again = client.post("/v1/tasks", json={"target": "quick", "world": "office"}).json()
        _until(lambda: _state(client, again["id"]) == "succeeded", what="a new task runs")
        events = [e for e in _sse_states(client, dripping["id"])]
        assert events[-1] == "failed"  # the final state event was written once space was back


def _sse_states(client: TestClient, task_id: str) -> list[str]:
    import json

    states = []
    with client.stream("GET", f"/v1/tasks/{task_id}/events") as stream:
        for line in stream.iter_lines():
            if line.startswith("data: "):
                data = json.loads(line[6:])
                if data.get("type") == "state":
                    states.append(data["state"])
    return states


def test_a_store_that_raises_gives_json_never_plain_text(make_settings: Make) -> None:
    with TestClient(create_app(make_settings()), raise_server_exceptions=False) as client:
        task = client.post("/v1/tasks", json={"target": "slow", "world": "office"}).json()
        with full_disk(client) as disk:
            disk.full = True
            for method, path in (("POST", "/v1/tasks"), ("DELETE", f"/v1/tasks/{task['id']}")):
                response = client.request(method, path,
                                          json={"target": "quick", "world": "office"})
                assert response.status_code == 503, (method, path, response.text)
                assert response.json()["detail"].startswith("storage error")
            disk.full = False
        assert client.delete(f"/v1/tasks/{task['id']}").status_code == 200


def test_an_unexpected_error_is_a_json_500(make_settings: Make,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    with TestClient(create_app(make_settings()), raise_server_exceptions=False) as client:
        def broken(*args: Any, **kwargs: Any) -> Any:
            raise RuntimeError("a bug")

        monkeypatch.setattr(client.app.state.manager.store, "page", broken)
        response = client.get("/v1/tasks")
        assert response.status_code == 500
        assert response.headers["content-type"] == "application/json"
        assert "internal error (RuntimeError)" in response.json()["detail"]


def test_a_dead_worker_thread_is_revived(make_settings: Make) -> None:
    """A slot thread that died (a bug) is started again by the supervisor: no restart."""
    with TestClient(create_app(make_settings())) as client:
        manager = client.app.state.manager
        pool = manager.episodes
        pool.jobs.put(None)  # ends one slot thread, as a crash in it would
        _until(lambda: not pool.alive(), what="the slot thread ended")
        _until(pool.alive, timeout=5, what="the slot thread revived")
        task = client.post("/v1/tasks", json={"target": "quick", "world": "office"}).json()
        _until(lambda: _state(client, task["id"]) == "succeeded", what="a task runs")


def test_store_marks_itself_degraded_until_a_write_works(tmp_path: Path) -> None:
    store = TaskStore(tmp_path / "s.sqlite3")
    page_count = store._conn.execute("PRAGMA page_count").fetchone()[0]
    store._conn.execute(f"PRAGMA max_page_count={page_count}")  # a real SQLITE_FULL
    with pytest.raises(StorageError, match=FULL):
        for i in range(50):
            store.insert(f"t{i}", {"target": "x" * 3000}, "me")
    assert store.write_error is not None and FULL in store.write_error
    assert not store.probe() or store.write_error is None
    store._conn.execute("PRAGMA max_page_count=1000000")
    assert store.probe() and store.write_error is None
    store.close()


# -- a damaged store at start-up ---------------------------------------------------------------

def _stored(data: Path, tasks: int = 200) -> Path:
    store = TaskStore(data / "avs.sqlite3")
    for i in range(tasks):
        store.insert(f"task{i:04d}", {"target": "cup", "pad": "x" * 500}, "me")
        store.add_event(f"task{i:04d}", {"type": "state", "pad": "y" * 500})
    store.close()
    return data / "avs.sqlite3"


@pytest.mark.parametrize("where", ["header", "page"])
def test_a_damaged_store_exits_6_with_one_line(tmp_path: Path, where: str,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    data = tmp_path / "data"
    data.mkdir()
    path = _stored(data)
    raw = bytearray(path.read_bytes())
    if where == "header":
        raw[:16] = b"this is not db!!"
    else:
        page = 4096
        middle = len(raw) // page // 2 * page
        raw[middle: middle + page] = b"\xde\xad\xbe\xef" * (page // 4)
    path.write_bytes(bytes(raw))
    code = main(["serve", "--data-dir", str(data), "--port", "0"])
    err = capsys.readouterr().err.strip()
    assert code == EXIT_STORE_CORRUPT == 6
    assert len(err.splitlines()) == 1, err
    assert str(path) in err and "move it aside" in err and "restore a backup" in err
    assert path.read_bytes() == bytes(raw)  # untouched
