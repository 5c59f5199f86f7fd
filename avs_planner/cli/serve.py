"""`avs serve`: run the HTTP service (FastAPI under uvicorn) on this machine."""

from __future__ import annotations

import argparse
import logging
import os
import socket
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from avs_planner.errors import AvsError

if TYPE_CHECKING:
    from api.config import Settings

EXIT_DATA_DIR_BUSY = 5  # another live `avs serve` holds the data dir's lock
EXIT_STORE_CORRUPT = 6  # the task store (DATA_DIR/avs.sqlite3) is damaged


class ServeError(AvsError):
    """The service cannot start with these settings."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "serve",
        help="run the HTTP service (tasks, events, plans, domain checks)",
        description="Serve the HTTP API. Settings come from AVS_* environment variables "
        "(AVS_API_KEY, AVS_API_KEYS, AVS_KEYS_FILE, AVS_DATA_DIR, ...); these options override "
        "them. Without keys the service is open and may only listen on a loopback address. "
        "Exit codes: 1 bad settings, data dir or port; 5 the data dir is in use; 6 the task "
        "store is damaged (restore a backup or move it aside).",
    )
    parser.add_argument("--host", help="address to listen on (default 127.0.0.1)")
    parser.add_argument("--port", type=int, help="TCP port (default 8000)")
    parser.add_argument("--data-dir", type=Path, help="tasks, events and results (SQLite)")
    parser.add_argument("--workers", type=int, help="worker processes running episodes")
    parser.add_argument("--ray-address", help="run episodes as Ray tasks on this cluster "
                        "(HOST:PORT, or 'local' to start Ray here; pip install '.[ray]')")
    parser.add_argument("--log-level", default="info", choices=["debug", "info", "warning"])
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from api.config import Settings, is_loopback

    overrides = {
        key: value
        for key, value in (("host", args.host), ("port", args.port),
                           ("data_dir", args.data_dir), ("workers", args.workers),
                           ("ray_address", args.ray_address))
        if value is not None
    }
    try:
        settings = Settings(**overrides)
    except ValidationError as exc:
        problems = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors())
        raise ServeError(f"bad service settings: {problems}") from exc
    if settings.is_open() and not is_loopback(settings.host):
        raise ServeError(
            f"refusing to listen on {settings.host} without an API key: set AVS_API_KEY "
            "(clients send it in X-API-Key) or use a loopback host such as 127.0.0.1"
        )
    from api import lock
    from api.security import KeyRing, KeySettingsError
    from api.server import bind

    try:
        KeyRing.from_settings(settings)
    except KeySettingsError as exc:
        raise ServeError(f"bad API keys: {exc}") from exc
    try:  # first: a busy port leaves nothing behind (no lock file, no store)
        sock = bind(settings.host, settings.port)
    except OSError as exc:
        raise ServeError(f"cannot listen on {settings.host}:{settings.port}: {exc}") from exc
    with sock:
        try:
            held = lock.acquire(settings.data_dir)  # before anything touches the store
        except lock.DataDirBusyError as exc:
            print(f"avs: error: {exc}", file=sys.stderr)
            return EXIT_DATA_DIR_BUSY
        except OSError as exc:
            raise ServeError(f"cannot use data dir {settings.data_dir}: {exc}") from exc
        try:
            damage = _check_data_dir(settings)
            if damage:
                print(f"avs: error: {damage}", file=sys.stderr)
                return EXIT_STORE_CORRUPT
            _check_ray(settings)
            return _serve(settings, sock, args.log_level)
        finally:
            lock.release(held)


def _check_data_dir(settings: Settings) -> str | None:
    """Open the task store and check it, so an unusable data dir is a clear error, not a
    traceback: `ServeError` when it cannot be used, a one-line message when it is damaged."""
    import sqlite3

    from api.store import TaskStore

    path = settings.db_path
    try:
        store = TaskStore(path)
    except sqlite3.DatabaseError as exc:
        if not _damaged(exc):
            raise ServeError(f"cannot use data dir {settings.data_dir}: {exc}") from exc
        return _corrupt(path, str(exc))
    except OSError as exc:
        raise ServeError(f"cannot use data dir {settings.data_dir}: {exc}") from exc
    try:
        problem = store.check()
    finally:
        store.close()
    return _corrupt(path, problem) if problem else None


def _damaged(exc: Exception) -> bool:
    text = str(exc).lower()
    return any(word in text for word in ("malformed", "not a database", "corrupt", "encrypted"))


def _corrupt(path: Path, why: str) -> str:
    return (f"the task store {path} is damaged ({why.splitlines()[0][:120]}); nothing was "
            f"changed: move it aside (mv {path} {path}.damaged, and its -wal and -shm files) "
            f"to start with an empty store, or restore a backup (api/README.md, Backups)")


def _check_ray(settings: Settings) -> None:
    if settings.ray_address:
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ServeError("--ray-address needs Ray: pip install '.[ray]'") from None


def _serve(settings: Settings, sock: socket.socket, log_level: str) -> int:
    from api.main import create_app
    from api.server import serve

    logging.basicConfig(level=log_level.upper(), format="%(levelname)s %(name)s: %(message)s")
    app = create_app(settings)
    port = sock.getsockname()[1]
    print(f"avs: serving on http://{settings.host}:{port} (pages at /, docs at /docs, "
          f"data in {settings.data_dir}, pid {os.getpid()})", flush=True)
    serve(app, settings, sock, log_level)
    return 0
