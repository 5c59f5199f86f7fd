"""SQLite (WAL) store for tasks, their event streams and results; safe to share across threads."""

from __future__ import annotations

import json
import sqlite3
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from api.schemas import TaskState

_SCHEMA = """
CREATE TABLE IF NOT EXISTS tasks (
    id TEXT PRIMARY KEY,
    state TEXT NOT NULL,
    request TEXT NOT NULL,
    owner TEXT NOT NULL,
    idempotency_key TEXT,
    request_hash TEXT,
    created_at REAL NOT NULL,
    started_at REAL,
    finished_at REAL,
    result TEXT,
    error TEXT,
    events INTEGER NOT NULL DEFAULT 0,
    attempts INTEGER NOT NULL DEFAULT 0,
    UNIQUE (owner, idempotency_key)
);
CREATE INDEX IF NOT EXISTS tasks_state ON tasks (state, created_at);
CREATE TABLE IF NOT EXISTS events (
    task_id TEXT NOT NULL REFERENCES tasks(id),
    seq INTEGER NOT NULL,
    data TEXT NOT NULL,
    PRIMARY KEY (task_id, seq)
);
"""


@dataclass(frozen=True)
class TaskRecord:
    """One row of `tasks`, decoded."""

    id: str
    state: TaskState
    request: dict[str, Any]
    owner: str
    idempotency_key: str | None
    request_hash: str | None
    created_at: float
    started_at: float | None
    finished_at: float | None
    result: dict[str, Any] | None
    error: str | None
    events: int
    attempts: int = 0  # times it started running (more than 1 after a requeue)


@dataclass(frozen=True)
class StoredEvent:
    seq: int
    data: dict[str, Any]


class TaskStore:
    """Tasks, events and results in one SQLite file; one connection guarded by a lock."""

    def __init__(self, path: Path):
        path.parent.mkdir(parents=True, exist_ok=True)
        self._conn = sqlite3.connect(path, check_same_thread=False, isolation_level=None)
        self._conn.execute("PRAGMA journal_mode=WAL")
        self._conn.execute("PRAGMA synchronous=NORMAL")
        self._conn.executescript(_SCHEMA)
        _migrate(self._conn)
        self._lock = threading.Lock()

    def close(self) -> None:
        with self._lock:
            self._conn.close()

    @contextmanager
    def _tx(self) -> Iterator[sqlite3.Connection]:
        with self._lock:
            self._conn.execute("BEGIN IMMEDIATE")
            try:
                yield self._conn
            except BaseException:
                self._conn.execute("ROLLBACK")
                raise
            self._conn.execute("COMMIT")

    def insert(
        self, task_id: str, request: dict[str, Any], owner: str,
        idempotency_key: str | None = None, request_hash: str | None = None,
    ) -> TaskRecord:
        """Add a queued task."""
        with self._tx() as db:
            db.execute(
                "INSERT INTO tasks (id, state, request, owner, idempotency_key, request_hash,"
                " created_at) VALUES (?, ?, ?, ?, ?, ?, ?)",
                (task_id, TaskState.QUEUED.value, json.dumps(request), owner,
                 idempotency_key, request_hash, time.time()),
            )
        record = self.get(task_id)
        assert record is not None
        return record

    def find_by_key(self, owner: str, idempotency_key: str) -> TaskRecord | None:
        """The task an owner already created with this Idempotency-Key, if any."""
        with self._lock:
            row = self._conn.execute(
                _SELECT + " WHERE t.owner=? AND t.idempotency_key=?", (owner, idempotency_key)
            ).fetchone()
        return _decode(row) if row is not None else None

    def get(self, task_id: str) -> TaskRecord | None:
        with self._lock:
            row = self._conn.execute(_SELECT + " WHERE t.id=?", (task_id,)).fetchone()
        return _decode(row) if row is not None else None

    def page(
        self, state: TaskState | None, limit: int, offset: int
    ) -> tuple[list[TaskRecord], int]:
        """A page of tasks, newest first, and how many match in all."""
        where, args = (" WHERE t.state=?", (state.value,)) if state else ("", ())
        with self._lock:
            rows = self._conn.execute(
                _SELECT + where + " ORDER BY t.created_at DESC, t.id LIMIT ? OFFSET ?",
                (*args, limit, offset),
            ).fetchall()
            count = self._conn.execute(f"SELECT count(*) FROM tasks t{where}", args).fetchone()
        return [_decode(r) for r in rows], int(count[0])

    def count_state(self, state: TaskState) -> int:
        with self._lock:
            row = self._conn.execute("SELECT count(*) FROM tasks WHERE state=?", (state.value,))
            return int(row.fetchone()[0])

    def ids_in_state(self, state: TaskState) -> list[str]:
        with self._lock:
            rows = self._conn.execute(
                "SELECT id FROM tasks WHERE state=? ORDER BY created_at, id", (state.value,)
            ).fetchall()
        return [r[0] for r in rows]

    def claim(self, task_id: str) -> bool:
        """queued → running, atomically; False if the task is no longer queued (e.g. cancelled)."""
        with self._tx() as db:
            cur = db.execute(
                "UPDATE tasks SET state=?, started_at=?, attempts=attempts+1"
                " WHERE id=? AND state=?",
                (TaskState.RUNNING.value, time.time(), task_id, TaskState.QUEUED.value),
            )
            return cur.rowcount == 1

    def finish(
        self, task_id: str, state: TaskState, result: dict[str, Any] | None, error: str | None,
        only_from: tuple[TaskState, ...] = (TaskState.QUEUED, TaskState.RUNNING),
    ) -> bool:
        """Move a live task to a terminal state with its result or error; False if not live."""
        marks = ",".join("?" for _ in only_from)
        with self._tx() as db:
            cur = db.execute(
                f"UPDATE tasks SET state=?, finished_at=?, result=?, error=? "
                f"WHERE id=? AND state IN ({marks})",
                (state.value, time.time(), json.dumps(result) if result is not None else None,
                 error, task_id, *(s.value for s in only_from)),
            )
            return cur.rowcount == 1

    def requeue(self, task_id: str) -> bool:
        with self._tx() as db:
            cur = db.execute(
                "UPDATE tasks SET state=?, started_at=NULL WHERE id=? AND state=?",
                (TaskState.QUEUED.value, task_id, TaskState.RUNNING.value),
            )
            return cur.rowcount == 1

    def add_event(self, task_id: str, data: dict[str, Any]) -> int:
        """Append an event to a task's stream; returns its sequence number (1, 2, ...)."""
        with self._tx() as db:
            row = db.execute("SELECT events FROM tasks WHERE id=?", (task_id,)).fetchone()
            seq = int(row[0]) + 1
            db.execute(
                "INSERT INTO events (task_id, seq, data) VALUES (?, ?, ?)",
                (task_id, seq, json.dumps(data, default=str)),
            )
            db.execute("UPDATE tasks SET events=? WHERE id=?", (seq, task_id))
            return seq

    def events_after(self, task_id: str, after: int, limit: int = 500) -> list[StoredEvent]:
        with self._lock:
            rows = self._conn.execute(
                "SELECT seq, data FROM events WHERE task_id=? AND seq>? ORDER BY seq LIMIT ?",
                (task_id, after, limit),
            ).fetchall()
        return [StoredEvent(int(seq), json.loads(data)) for seq, data in rows]


_SELECT = (
    "SELECT t.id, t.state, t.request, t.owner, t.idempotency_key, t.request_hash, t.created_at,"
    " t.started_at, t.finished_at, t.result, t.error, t.events, t.attempts FROM tasks t"
)


def _decode(row: tuple[Any, ...]) -> TaskRecord:
    return TaskRecord(
        id=row[0], state=TaskState(row[1]), request=json.loads(row[2]), owner=row[3],
        idempotency_key=row[4], request_hash=row[5], created_at=row[6], started_at=row[7],
        finished_at=row[8], result=json.loads(row[9]) if row[9] else None, error=row[10],
        events=int(row[11]), attempts=int(row[12]),
    )


def _migrate(conn: sqlite3.Connection) -> None:
    """Bring a store written by an older version up to this schema."""
    columns = {row[1] for row in conn.execute("PRAGMA table_info(tasks)")}
    if "attempts" not in columns:
        conn.execute("ALTER TABLE tasks ADD COLUMN attempts INTEGER NOT NULL DEFAULT 0")
