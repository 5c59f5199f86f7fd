"""/docs (Swagger UI) and /redoc served from files on this machine: nothing loads from a CDN.

The assets come from the `fastapi-offline` package (Swagger UI 5, which reads OpenAPI 3.1, and
ReDoc), located on disk and served as static files; its app class is not used. Without the
package the pages say how to get it and link the raw schema.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from fastapi import FastAPI
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
from fastapi.responses import HTMLResponse
from fastapi.staticfiles import StaticFiles

ASSETS_URL = "/docs-assets"
_MISSING = (
    "<!doctype html><title>{title}</title><p>The API documentation pages need the "
    "<code>fastapi-offline</code> package (pip install fastapi-offline). The schema itself is "
    "at <a href=\"{schema}\">{schema}</a>.</p>"
)


def asset_dir() -> Path | None:
    """The bundled Swagger UI / ReDoc files, if the package is installed."""
    spec = importlib.util.find_spec("fastapi_offline")
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(next(iter(spec.submodule_search_locations))) / "static"
    return path if (path / "swagger-ui-bundle.js").is_file() else None


def add_docs(app: FastAPI) -> None:
    """Add /docs and /redoc (create the app with docs_url=None, redoc_url=None)."""
    assets = asset_dir()
    title = f"{app.title} API"
    schema = app.openapi_url or "/openapi.json"
    if assets is not None:
        app.mount(ASSETS_URL, StaticFiles(directory=assets), name="docs-assets")

    @app.get("/docs", include_in_schema=False)
    async def swagger_ui() -> HTMLResponse:
        if assets is None:
            return HTMLResponse(_MISSING.format(title=title, schema=schema))
        return get_swagger_ui_html(
            openapi_url=schema, title=title,
            swagger_js_url=f"{ASSETS_URL}/swagger-ui-bundle.js",
            swagger_css_url=f"{ASSETS_URL}/swagger-ui.css",
            swagger_favicon_url=f"{ASSETS_URL}/favicon.png",
        )

    @app.get("/redoc", include_in_schema=False)
    async def redoc() -> HTMLResponse:
        if assets is None:
            return HTMLResponse(_MISSING.format(title=title, schema=schema))
        return get_redoc_html(
            openapi_url=schema, title=title, redoc_js_url=f"{ASSETS_URL}/redoc.standalone.js",
            redoc_favicon_url=f"{ASSETS_URL}/favicon.png", with_google_fonts=False,
        )
