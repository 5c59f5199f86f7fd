"""The real episode runner, with each event stamped `sent` (epoch seconds) as the worker emits
it: the browser test measures from there to the moment the task page has shown the event."""

from __future__ import annotations

import time
from typing import Any

from avs_planner.jobs import run_episode


def run(spec: dict[str, Any], emit: Any, should_stop: Any) -> dict[str, Any]:
    return run_episode(spec, lambda event: emit({**event, "sent": time.time()}), should_stop)
