"""The app factory: settings in, a FastAPI app out (routes under /v1, workers in its lifespan)."""

from __future__ import annotations

import logging
import re
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
from api.manager import TaskManager
from api.middleware import BodyLimitMiddleware
from api.pages import add_pages
from api.plan_jobs import PlanJobs
from api.routes import domains, misc, plans, tasks
from api.security import RateLimiter
from api.store import TaskStore
from api.worlds import default_worlds_dir
from avs_planner import __version__

log = logging.getLogger("avs.api")
API_PREFIX = "/v1"
_BODY_PARSE_ERROR = "There was an error parsing the body"  # FastAPI's 400 for undecodable JSON


def create_app(settings: Settings | None = None) -> FastAPI:
    """A ready-to-serve app; its lifespan locks the data dir, opens the store and starts the
    worker processes. `app.state.draining` (set on a stop signal) ends open event streams."""
    settings = settings or Settings()
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
        _log_access_mode(settings)
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
    app.state.draining = threading.Event()
    app.state.rate_limiter = RateLimiter(settings.rate_limit_per_minute, settings.rate_limit_burst)
    for module in (tasks, plans, domains, misc):
        app.include_router(module.router, prefix=API_PREFIX)
    add_docs(app)
    add_pages(app)
    _add_error_handlers(app)
    return app


def _log_access_mode(settings: Settings) -> None:
    if settings.is_open():
        log.warning(
            "AVS_API_KEY is not set: mutating calls need no key, so the service must only listen "
            "on a loopback address (here %s)", settings.host,
        )
    else:
        log.info("API key required in X-API-Key for POST and DELETE calls")


def _add_error_handlers(app: FastAPI) -> None:
    @app.exception_handler(RequestValidationError)
    async def validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
        errors = [{k: v for k, v in e.items() if k in ("type", "loc", "msg")} for e in exc.errors()]
        return JSONResponse({"detail": errors}, status.HTTP_422_UNPROCESSABLE_CONTENT)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> Response:
        if exc.status_code == 405:
            return _method_not_allowed(request)
        if exc.status_code == 400 and exc.detail == _BODY_PARSE_ERROR:
            detail = [{"type": "json_invalid", "loc": ["body"],
                       "msg": "the body is not valid JSON text (UTF-8)"}]
            return JSONResponse({"detail": detail}, status.HTTP_422_UNPROCESSABLE_CONTENT)
        return await http_exception_handler(request, exc)


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
