"""Errors of the viewer extra, and the one place that imports rerun."""

from __future__ import annotations

import os
import sys
from types import ModuleType

INSTALL = "pip install 'avs-planner[viewer]'"


class ViewerError(RuntimeError):
    """A recording could not be written, read or shown (the message says why)."""


class ViewerMissingError(ViewerError):
    """rerun-sdk is not installed."""


def display_missing() -> str | None:
    """Why no viewer window can open here (None: it may)."""
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                 or os.environ.get("WAYLAND_DISPLAY")):
        return "no display here (DISPLAY and WAYLAND_DISPLAY are not set)"
    return None


def require_rerun(why: str = "recording an episode") -> ModuleType:
    """The rerun module, or a ViewerMissingError saying how to install it."""
    try:
        import rerun
    except ImportError:
        raise ViewerMissingError(f"{why} needs the Rerun SDK (rerun-sdk), which is not "
                                 f"installed: {INSTALL}") from None
    return rerun
