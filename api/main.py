"""The app factory: settings in, a FastAPI app out (routes under /v1, workers in its lifespan)."""

from __future__ import annotations

import logging
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

from fastapi import FastAPI, Request, status
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse

from api.config import Settings
from api.manager import TaskManager
from api.middleware import BodyLimitMiddleware
from api.routes import domains, misc, plans, tasks
from api.security import RateLimiter
from api.store import TaskStore
from api.worlds import default_worlds_dir
from avs_planner import __version__

log = logging.getLogger("avs.api")
API_PREFIX = "/v1"


def create_app(settings: Settings | None = None) -> FastAPI:
    """A ready-to-serve app; its lifespan opens the store and starts the worker processes."""
    settings = settings or Settings()
    if settings.worlds_dir is None:
        settings = settings.model_copy(update={"worlds_dir": default_worlds_dir()})

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        store = TaskStore(settings.db_path)
        manager = TaskManager(settings, store)
        manager.start()
        app.state.manager = manager
        _log_access_mode(settings)
        try:
            yield
        finally:
            manager.stop()
            store.close()

    app = FastAPI(
        title="avs-planner",
        version=__version__,
        summary="Find objects in buildings: tasks, live events, planning and domain checks.",
        lifespan=lifespan,
    )
    app.add_middleware(BodyLimitMiddleware, max_bytes=settings.max_body_bytes)
    app.state.settings = settings
    app.state.rate_limiter = RateLimiter(settings.rate_limit_per_minute, settings.rate_limit_burst)
    for module in (tasks, plans, domains, misc):
        app.include_router(module.router, prefix=API_PREFIX)
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
