"""Import PyBullet without its build-time banner.

PyBullet's C module prints "pybullet build time: ..." on stderr when it is first imported,
so every `avs` command (and every worker process) began with a line that says nothing to a
user. `sim/__init__.py` imports this module first: it imports pybullet once with file
descriptor 2 pointed at /dev/null, then puts stderr back. An import error is raised after
stderr is restored, so it is still shown. Where stderr has no file descriptor (an embedding
that replaced it), pybullet is imported as is.
"""

from __future__ import annotations

import os
import sys


def _import_quietly() -> None:
    if "pybullet" in sys.modules:
        return
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (AttributeError, OSError, ValueError):
        import pybullet  # noqa: F401
        return
    try:
        quiet = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(quiet, 2)
        finally:
            os.close(quiet)
        import pybullet  # noqa: F401
    finally:
        os.dup2(saved, 2)
        os.close(saved)


_import_quietly()
