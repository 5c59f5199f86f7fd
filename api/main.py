"""The app factory: settings in, a FastAPI app out (routes under /v1, workers in its lifespan)."""

from __future__ import annotations

import logging
import re
import sqlite3
import threading
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

from fastapi import FastAPI, Request, Response, status
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from api import lock
from api.config import Settings
from api.docs import add_docs
from api.limits import bounded, short
from api.manager import TaskManager
from api.middleware import BodyLimitMiddleware
from api.pages import add_pages
from api.plan_jobs import PlanJobs
from api.routes import buildings, domains, misc, plans, tasks
from api.security import KeyRing, RateLimiter
from api.store import StorageError, TaskStore
from api.worlds import default_worlds_dir
from avs_planner import __version__

log = logging.getLogger("avs.api")
API_PREFIX = "/v1"
_BODY_PARSE_ERROR = "There was an error parsing the body"  # FastAPI's 400 for undecodable JSON


def create_app(settings: Settings | None = None) -> FastAPI:
    """A ready-to-serve app; its lifespan locks the data dir, opens the store and starts the
    worker processes. `app.state.draining` (set on a stop signal) ends open event streams.
    `KeySettingsError` when the key settings are wrong."""
    settings = settings or Settings()
    keys = KeyRing.from_settings(settings)
    if settings.worlds_dir is None:
        settings = settings.model_copy(update={"worlds_dir": default_worlds_dir()})

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        held = lock.acquire(settings.data_dir)  # before the store: no recovery under a live one
        store = TaskStore(settings.db_path)
        manager = TaskManager(settings, store, app.state.draining)
        manager.start()
        app.state.manager = manager
        app.state.plan_jobs = PlanJobs(manager, settings.plan_results_kept)
        _log_access_mode(settings, keys)
        try:
            yield
        finally:
            app.state.draining.set()
            app.state.plan_jobs.stop()
            manager.stop()
            store.close()
            lock.release(held)

    app = FastAPI(
        title="avs-planner",
        version=__version__,
        summary="Find objects in buildings: tasks, live events, planning and domain checks.",
        lifespan=lifespan, docs_url=None, redoc_url=None,
    )
    app.add_middleware(BodyLimitMiddleware, max_bytes=settings.max_body_bytes)
    app.state.settings = settings
    app.state.keys = keys
    app.state.draining = threading.Event()
    app.state.rate_limiter = RateLimiter(settings.rate_limit_per_minute, settings.rate_limit_burst)
    for module in (tasks, buildings, plans, domains, misc):
        app.include_router(module.router, prefix=API_PREFIX)
    add_docs(app)
    add_pages(app)
    _add_error_handlers(app)
    return app


def _log_access_mode(settings: Settings, keys: KeyRing) -> None:
    if keys.open:
        log.warning(
            "no API keys are set (AVS_API_KEY, AVS_API_KEYS, AVS_KEYS_FILE): calls need no "
            "key, so the service must only listen on a loopback address (here %s)",
            settings.host,
        )
        return
    roles = ", ".join(f"{k.name} ({k.role.label})" for k in keys.keys)
    reads = "open to anyone (AVS_OPEN_READS)" if keys.open_reads else "need a key too"
    log.info("%d API key(s) in X-API-Key: %s; reads %s", len(keys.keys), roles, reads)


def _add_error_handlers(app: FastAPI) -> None:
    """Every error is JSON with a bounded `detail`: validation errors keep only type, loc and
    msg (never the input, which may be huge), each string cut to a short excerpt."""

    @app.exception_handler(RequestValidationError)
    async def validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
        errors = [{"type": e.get("type"), "loc": [short(str(x), 64) if isinstance(x, str)
                                                  else x for x in e.get("loc", ())],
                   "msg": short(str(e.get("msg", "")))} for e in exc.errors()]
        return JSONResponse({"detail": bounded(errors)}, status.HTTP_422_UNPROCESSABLE_CONTENT)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> Response:
        if exc.status_code == 405:
            return _method_not_allowed(request)
        if exc.status_code == 400 and exc.detail == _BODY_PARSE_ERROR:
            detail = [{"type": "json_invalid", "loc": ["body"],
                       "msg": "the body is not valid JSON text (UTF-8)"}]
            return JSONResponse({"detail": detail}, status.HTTP_422_UNPROCESSABLE_CONTENT)
        exc.detail = bounded(exc.detail)
        return await http_exception_handler(request, exc)

    @app.exception_handler(StorageError)
    @app.exception_handler(sqlite3.Error)
    async def storage_error(request: Request, exc: Exception) -> JSONResponse:
        log.error("%s %s: storage error: %s", request.method, request.url.path, exc)
        message = str(exc) if isinstance(exc, StorageError) else f"storage error: {exc}"
        return JSONResponse(
            {"detail": short(f"{message}; retry later (see /v1/health)")},
            status.HTTP_503_SERVICE_UNAVAILABLE, headers={"Retry-After": "10"})

    @app.exception_handler(Exception)
    async def internal_error(request: Request, exc: Exception) -> JSONResponse:
        # a bug: logged with its traceback by the server; the client gets JSON, not text
        return JSONResponse(
            {"detail": short(f"internal error ({type(exc).__name__}); the service log has "
                             "the details")}, status.HTTP_500_INTERNAL_SERVER_ERROR)


def _method_not_allowed(request: Request) -> Response:
    """405 with every method the path has in `Allow` (Starlette names only the first route's),
    read from the OpenAPI paths; OPTIONS gets 204 with the same header."""
    methods: set[str] = {"OPTIONS"}
    for template, operations in request.app.openapi()["paths"].items():
        pattern = re.sub(r"\\{[^/]+?\\}", "[^/]+", re.escape(template))
        if re.fullmatch(pattern, request.url.path):
            methods |= {m.upper() for m in operations}
    for route in request.app.routes:  # the pages, which are not in the schema
        regex, route_methods = getattr(route, "path_regex", None), getattr(route, "methods", None)
        if regex is not None and route_methods and not getattr(route, "include_in_schema", True) \
                and regex.fullmatch(request.url.path):
            methods |= set(route_methods)
    if "GET" in methods:
        methods.add("HEAD")
    headers = {"Allow": ", ".join(sorted(methods))}
    if request.method == "OPTIONS":
        return Response(status_code=status.HTTP_204_NO_CONTENT, headers=headers)
    return JSONResponse({"detail": "Method Not Allowed"}, status.HTTP_405_METHOD_NOT_ALLOWED,
                        headers=headers)
