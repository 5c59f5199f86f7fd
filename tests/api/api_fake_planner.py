"""An injected plan job for testing the plan pool (fairness, cancellation) without a search
that happens to be slow: a problem text `sleep S` stands for a search of S seconds; anything
else goes to the real planner. Loaded by file path in the worker (`AVS_PLAN_RUNNER`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

RUNNER = f"{Path(__file__).resolve()}:plan"


def plan(domain_text: str, problem_text: str, options: dict[str, Any] | None = None) -> dict:
    if problem_text.startswith("sleep "):
        seconds = float(problem_text.split()[1])
        time.sleep(seconds)
        return {"status": "timeout", "plan": [], "planning_time_s": seconds}
    from avs_planner import jobs

    return jobs.plan(domain_text, problem_text, options)
