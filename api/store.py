"""SQLite (WAL) store for tasks, their event streams and results; safe to share across threads.

A write that fails (`database or disk is full`, an I/O error) raises `StorageError` and leaves
the store *degraded* (`write_error` says why) until a write succeeds again; `probe()` tries a
tiny one, so the service notices when space is back even while nothing else writes.
"""

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
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT);
CREATE TABLE IF NOT EXISTS buildings (
    id TEXT PRIMARY KEY,
    world TEXT NOT NULL,
    created_at REAL NOT NULL
);
"""


class StorageError(Exception):
    """A write to the store failed (e.g. the disk is full); the message says why."""


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
    building: str | None = None  # the building whose memory it reads and keeps (None once
    # that building was forgotten; its request still names it)


@dataclass(frozen=True)
class BuildingRecord:
    """One row of `buildings`: a building the service keeps a memory of, the world it is
    (JSON: a built-in world's name, a generated building's arguments or an inline file's
    hash), and when its first task (since it was last forgotten) was submitted."""

    id: str
    world: str
    created_at: float


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
        self.write_error: str | None = None  # why the last write failed; None once one works
        self.write_error_since: float | None = None

    def close(self) -> None:
        with self._lock:
            self._conn.close()

    @contextmanager
    def _tx(self) -> Iterator[sqlite3.Connection]:
        """A write transaction; a failing write raises `StorageError` and marks the store
        degraded, a successful one clears that."""
        with self._lock:
            try:
                self._conn.execute("BEGIN IMMEDIATE")
            except sqlite3.Error as exc:
                raise self._failed(exc) from exc
            try:
                yield self._conn
                self._conn.execute("COMMIT")
            except BaseException as exc:
                self._rollback()
                if isinstance(exc, sqlite3.Error):
                    raise self._failed(exc) from exc
                raise
            if self.write_error is not None:
                self.write_error = self.write_error_since = None

    def _rollback(self) -> None:
        try:
            self._conn.execute("ROLLBACK")
        except sqlite3.Error:
            pass  # SQLite rolled back itself (e.g. after SQLITE_FULL), or nothing was open

    def _failed(self, exc: sqlite3.Error) -> StorageError:
        message = f"storage error: {exc}"
        if self.write_error is None:
            self.write_error_since = time.time()
        self.write_error = message
        return StorageError(message)

    def probe(self) -> bool:
        """Try a tiny write; True (and no longer degraded) when it worked."""
        try:
            with self._tx() as db:
                db.execute("INSERT OR REPLACE INTO meta (key, value) VALUES ('probe', ?)",
                           (str(time.time()),))
        except StorageError:
            return False
        return True

    def check(self) -> str | None:
        """Why the database file is damaged (SQLite's quick_check, then reading every row),
        or None; for start-up, before any task is touched."""
        with self._lock:
            try:
                rows = self._conn.execute("PRAGMA quick_check").fetchall()
                if rows != [("ok",)]:
                    return "; ".join(str(r[0]) for r in rows[:3])
                for table in ("tasks", "events", "buildings"):
                    for _ in self._conn.execute(f"SELECT * FROM {table}"):  # noqa: S608
                        pass
            except sqlite3.DatabaseError as exc:
                return str(exc)
        return None

    def insert(
        self, task_id: str, request: dict[str, Any], owner: str,
        idempotency_key: str | None = None, request_hash: str | None = None,
        building: tuple[str, str] | None = None,
    ) -> TaskRecord:
        """Add a queued task; `building` (id, world) records the building it runs in (made
        known when new)."""
        now = time.time()
        with self._tx() as db:
            db.execute(
                "INSERT INTO tasks (id, state, request, owner, idempotency_key, request_hash,"
                " created_at, building) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (task_id, TaskState.QUEUED.value, json.dumps(request), owner,
                 idempotency_key, request_hash, now, building[0] if building else None),
            )
            if building is not None:
                db.execute("INSERT OR IGNORE INTO buildings (id, world, created_at) "
                           "VALUES (?, ?, ?)", (*building, now))
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
        self, state: TaskState | None, limit: int, offset: int, owner: str | None = None
    ) -> tuple[list[TaskRecord], int]:
        """A page of tasks (of `owner`, if given), newest first, and how many match in all."""
        clauses, values = [], []
        if state:
            clauses.append("t.state=?")
            values.append(state.value)
        if owner is not None:
            clauses.append("t.owner=?")
            values.append(owner)
        where = " WHERE " + " AND ".join(clauses) if clauses else ""
        args = tuple(values)
        with self._lock:
            rows = self._conn.execute(
                _SELECT + where + " ORDER BY t.created_at DESC, t.id LIMIT ? OFFSET ?",
                (*args, limit, offset),
            ).fetchall()
            count = self._conn.execute(f"SELECT count(*) FROM tasks t{where}", args).fetchone()
        return [_decode(r) for r in rows], int(count[0])

    def count_state(self, state: TaskState, owner: str | None = None) -> int:
        sql, args = "SELECT count(*) FROM tasks WHERE state=?", (state.value,)
        if owner is not None:
            sql, args = sql + " AND owner=?", (*args, owner)
        with self._lock:
            return int(self._conn.execute(sql, args).fetchone()[0])

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

    # -- buildings ------------------------------------------------------------------------

    def building(self, building_id: str) -> BuildingRecord | None:
        with self._lock:
            row = self._conn.execute("SELECT id, world, created_at FROM buildings WHERE id=?",
                                     (building_id,)).fetchone()
        return BuildingRecord(*row) if row is not None else None

    def buildings(self) -> list[BuildingRecord]:
        """Every known building, by id."""
        with self._lock:
            rows = self._conn.execute(
                "SELECT id, world, created_at FROM buildings ORDER BY id").fetchall()
        return [BuildingRecord(*row) for row in rows]

    def building_tasks(self, building_id: str, limit: int = 100) -> tuple[list[TaskRecord], int]:
        """The newest `limit` tasks of a building's memory (since it was last forgotten),
        newest first, and how many it has in all."""
        with self._lock:
            rows = self._conn.execute(
                _SELECT + " WHERE t.building=? ORDER BY t.created_at DESC, t.id LIMIT ?",
                (building_id, limit)).fetchall()
            count = self._conn.execute("SELECT count(*) FROM tasks WHERE building=?",
                                       (building_id,)).fetchone()
        return [_decode(r) for r in rows], int(count[0])

    def building_live(self, building_id: str) -> int:
        """Tasks of the building still queued or running."""
        with self._lock:
            row = self._conn.execute(
                "SELECT count(*) FROM tasks WHERE building=? AND state IN (?, ?)",
                (building_id, TaskState.QUEUED.value, TaskState.RUNNING.value)).fetchone()
        return int(row[0])

    def forget_building(self, building_id: str) -> bool:
        """Drop the building (False: there was none); its tasks stay, no longer counted as
        its (their requests still name it)."""
        with self._tx() as db:
            cur = db.execute("DELETE FROM buildings WHERE id=?", (building_id,))
            db.execute("UPDATE tasks SET building=NULL WHERE building=?", (building_id,))
            return cur.rowcount == 1

    def events_after(self, task_id: str, after: int, limit: int = 500) -> list[StoredEvent]:
        with self._lock:
            rows = self._conn.execute(
                "SELECT seq, data FROM events WHERE task_id=? AND seq>? ORDER BY seq LIMIT ?",
                (task_id, after, limit),
            ).fetchall()
        return [StoredEvent(int(seq), json.loads(data)) for seq, data in rows]


_SELECT = (
    "SELECT t.id, t.state, t.request, t.owner, t.idempotency_key, t.request_hash, t.created_at,"
    " t.started_at, t.finished_at, t.result, t.error, t.events, t.attempts, t.building"
    " FROM tasks t"
)


def _decode(row: tuple[Any, ...]) -> TaskRecord:
    return TaskRecord(
        id=row[0], state=TaskState(row[1]), request=json.loads(row[2]), owner=row[3],
        idempotency_key=row[4], request_hash=row[5], created_at=row[6], started_at=row[7],
        finished_at=row[8], result=json.loads(row[9]) if row[9] else None, error=row[10],
        events=int(row[11]), attempts=int(row[12]), building=row[13],
    )


def _migrate(conn: sqlite3.Connection) -> None:
    """Bring a store written by an older version up to this schema."""
    columns = {row[1] for row in conn.execute("PRAGMA table_info(tasks)")}
    if "attempts" not in columns:
        conn.execute("ALTER TABLE tasks ADD COLUMN attempts INTEGER NOT NULL DEFAULT 0")
    if "building" not in columns:  # stores before buildings: no task ran in one
        conn.execute("ALTER TABLE tasks ADD COLUMN building TEXT")
    conn.execute("CREATE INDEX IF NOT EXISTS tasks_building ON tasks (building, created_at)")
