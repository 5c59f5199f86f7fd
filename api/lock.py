"""One service per data dir: an exclusive, non-blocking `flock` on `DATA_DIR/avs.lock`.

Taken before anything opens the task store, so a second instance (a double `make serve`, a
restart race) never runs restart recovery against a live instance's tasks. The kernel drops the
lock when the holder dies, even by SIGKILL, so a stale lock file never blocks a restart. The
lock is per process and reentrant: the CLI takes it first, the app's lifespan takes it again.
"""

from __future__ import annotations

import fcntl
import os
import threading
from pathlib import Path

from avs_planner.errors import AvsError

LOCK_NAME = "avs.lock"


class DataDirBusyError(AvsError):
    """Another live process holds the data dir's lock."""


_held: dict[Path, tuple[int, int]] = {}  # resolved lock path -> (fd, holders in this process)
_guard = threading.Lock()


def lock_path(data_dir: Path) -> Path:
    return data_dir / LOCK_NAME


def acquire(data_dir: Path) -> Path:
    """Hold the data dir's lock (creating the dir); `DataDirBusyError` names the holder's pid."""
    data_dir.mkdir(parents=True, exist_ok=True)
    path = lock_path(data_dir).resolve()
    with _guard:
        if path in _held:
            fd, count = _held[path]
            _held[path] = (fd, count + 1)
            return path
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _read_pid(fd)
            os.close(fd)
            raise DataDirBusyError(
                f"data dir {data_dir} is in use by another avs serve (pid {holder}); stop it or "
                "use another --data-dir") from None
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        _held[path] = (fd, 1)
        return path


def release(path: Path) -> None:
    """Give back one hold; the lock is dropped when the last holder in this process lets go."""
    with _guard:
        if path not in _held:
            return
        fd, count = _held[path]
        if count > 1:
            _held[path] = (fd, count - 1)
            return
        del _held[path]
        os.close(fd)  # closing the descriptor drops the flock


def _read_pid(fd: int) -> str:
    try:
        text = os.pread(fd, 32, 0).decode(errors="replace").strip()
    except OSError:
        return "unknown"
    return text or "unknown"
