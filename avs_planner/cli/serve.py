"""`avs serve`: run the HTTP service (FastAPI under uvicorn) on this machine."""

from __future__ import annotations

import argparse
import logging
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from avs_planner.errors import AvsError

if TYPE_CHECKING:
    from api.config import Settings

EXIT_DATA_DIR_BUSY = 5  # another live `avs serve` holds the data dir's lock


class ServeError(AvsError):
    """The service cannot start with these settings."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "serve",
        help="run the HTTP service (tasks, events, plans, domain checks)",
        description="Serve the HTTP API. Settings come from AVS_* environment variables "
        "(AVS_API_KEY, AVS_DATA_DIR, ...); these options override them. Without AVS_API_KEY "
        "the service is open and may only listen on a loopback address.",
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

    try:
        held = lock.acquire(settings.data_dir)  # before anything touches the store
    except lock.DataDirBusyError as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return EXIT_DATA_DIR_BUSY
    except OSError as exc:
        raise ServeError(f"cannot use data dir {settings.data_dir}: {exc}") from exc
    try:
        _check_data_dir(settings)
        _check_ray(settings)
        return _serve(settings, args.log_level)
    finally:
        lock.release(held)


def _check_data_dir(settings: Settings) -> None:
    """Open the task store once, so an unusable data dir is a clear error, not a traceback."""
    import sqlite3

    from api.store import TaskStore

    try:
        TaskStore(settings.db_path).close()
    except (OSError, sqlite3.Error) as exc:
        raise ServeError(f"cannot use data dir {settings.data_dir}: {exc}") from exc


def _check_ray(settings: Settings) -> None:
    if settings.ray_address:
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ServeError("--ray-address needs Ray: pip install '.[ray]'") from None


def _serve(settings: Settings, log_level: str) -> int:
    from api.main import create_app
    from api.server import bind, serve

    try:
        sock = bind(settings.host, settings.port)
    except OSError as exc:
        raise ServeError(f"cannot listen on {settings.host}:{settings.port}: {exc}") from exc
    logging.basicConfig(level=log_level.upper(), format="%(levelname)s %(name)s: %(message)s")
    app = create_app(settings)
    print(f"avs: serving on http://{settings.host}:{settings.port} (pages at /, docs at /docs, "
          f"data in {settings.data_dir}, pid {os.getpid()})", flush=True)
    with sock:
        serve(app, settings, sock, log_level)
    return 0
