"""Running a page's script under Node with the minimal DOM of `pages_dom_shim.js` (the page's
own `AVS.el`), for the tests of the task page's cards. Tests that need it are skipped
without Node; the browser tests open a real page."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

from api.pages import STATIC

NODE = shutil.which("node") or shutil.which("nodejs")
needs_node = pytest.mark.skipif(NODE is None, reason="no node (Node.js) on PATH to run the "
                                "page's script")
SHIM = Path(__file__).with_name("pages_dom_shim.js")


def run_js(script: str, data: Any) -> str:
    """What `script` (a statement over the page's globals and `data`) prints under Node."""
    result = subprocess.run([str(NODE), str(SHIM), str(STATIC)],
                            input=json.dumps({"script": script, "data": data}),
                            capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    return result.stdout
