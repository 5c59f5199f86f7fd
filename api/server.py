"""Running the app under uvicorn: bind first, trust proxy headers only when told, drain on stop."""

from __future__ import annotations

import socket
from types import FrameType

import uvicorn
from fastapi import FastAPI

from api.config import Settings

GRACEFUL_SHUTDOWN_S = 3.0  # backstop: requests still open this long after SIGTERM are cut


class DrainingServer(uvicorn.Server):
    """uvicorn's server, but a stop signal first tells the app to end its event streams (which
    otherwise last as long as their task), so a SIGTERM takes seconds, not the task limit."""

    def __init__(self, config: uvicorn.Config, app: FastAPI):
        super().__init__(config)
        self.app = app

    def handle_exit(self, sig: int, frame: FrameType | None) -> None:
        self.app.state.draining.set()
        super().handle_exit(sig, frame)


def bind(host: str, port: int) -> socket.socket:
    """The listening socket, bound before the app starts (so a busy port fails early, cleanly)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((host, port))
        sock.set_inheritable(True)
    except OSError:
        sock.close()
        raise
    return sock


def serve(app: FastAPI, settings: Settings, sock: socket.socket, log_level: str) -> None:
    """Serve `app` on `sock` until a stop signal. Proxy headers (X-Forwarded-For) are trusted
    only from `AVS_FORWARDED_ALLOW_IPS`; by default from nobody."""
    trusted = settings.forwarded_allow_ips
    config = uvicorn.Config(
        app, log_level=log_level, proxy_headers=bool(trusted), forwarded_allow_ips=trusted or "",
        timeout_graceful_shutdown=GRACEFUL_SHUTDOWN_S,
    )
    DrainingServer(config, app).run(sockets=[sock])
