"""Importing the simulator prints nothing: PyBullet's build-time banner is held back."""

from __future__ import annotations

import subprocess
import sys


def test_importing_sim_prints_no_pybullet_banner() -> None:
    code = "import sim, pybullet; print(pybullet.isConnected())"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=True)
    assert "pybullet build time" not in done.stderr + done.stdout
    assert done.stdout.strip() == "0"  # pybullet itself is there and works


def test_an_error_after_the_import_still_reaches_stderr() -> None:
    done = subprocess.run([sys.executable, "-c", "import sim, sys; sys.exit('after import')"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 1 and "after import" in done.stderr
