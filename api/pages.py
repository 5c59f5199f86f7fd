"""The pages: the task list with a submit form at `/`, a task page at `/tasks/{id}`, the
buildings the service remembers at `/buildings` and one at `/buildings/{id}`.

Plain HTML, CSS and JavaScript shipped in `api/static/` (package data), served as they are:
no build step, nothing from a CDN. The pages call the API under /v1 like any client, with the
key (when the service has one) in the `X-API-Key` header, never in a URL.
"""

from __future__ import annotations

from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles

STATIC = Path(__file__).with_name("static")
ASSETS_URL = "/ui"
_HEADERS = {
    # scripts, styles and connections from this origin only; the map's grid arrives as a
    # data: PNG
    "Content-Security-Policy": "default-src 'self'; img-src 'self' data: blob:; "
    "object-src 'none'; base-uri 'none'; frame-ancestors 'none'; form-action 'self'",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-cache",
}


def add_pages(app: FastAPI) -> None:
    """Add `/`, `/tasks/{task_id}`, `/buildings`, `/buildings/{building_id}` and the files
    under /ui."""
    app.mount(ASSETS_URL, StaticFiles(directory=STATIC), name="ui")

    @app.get("/", include_in_schema=False)
    async def task_list() -> FileResponse:
        return FileResponse(STATIC / "index.html", headers=_HEADERS)

    @app.get("/tasks/{task_id}", include_in_schema=False)
    async def task_page(task_id: str) -> FileResponse:
        # the page reads the task from /v1 and says so when there is no such task
        return FileResponse(STATIC / "task.html", headers=_HEADERS)

    @app.get("/buildings", include_in_schema=False)
    async def building_list() -> FileResponse:
        return FileResponse(STATIC / "buildings.html", headers=_HEADERS)

    @app.get("/buildings/{building_id}", include_in_schema=False)
    async def building_page(building_id: str) -> FileResponse:
        # the page reads the building from /v1 and says so when there is none
        return FileResponse(STATIC / "buildings.html", headers=_HEADERS)
