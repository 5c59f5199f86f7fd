"""Property test over the OpenAPI schema (schemathesis): no generated request gets a 5xx or a
status code its operation does not document.

Valid (positive) and invalid (negative) requests for every operation, plus the task routes on
real tasks in several states (ended, running, queued), so their life cycle is fuzzed too. The
default run is small; `-m slow` runs a larger one.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
import schemathesis
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis.errors import Unsatisfiable
from hypothesis.strategies import SearchStrategy

from api.config import Settings
from api.main import create_app

MODES = (schemathesis.GenerationMode.POSITIVE, schemathesis.GenerationMode.NEGATIVE)


def _fuzz_all(make_settings: Callable[..., Settings], examples: int) -> tuple[list[str], int]:
    app = create_app(make_settings(rate_limit_per_minute=1e6, rate_limit_burst=10**6,
                                   queue_size=10**6, plan_time_limit_s=30))
    schema = schemathesis.openapi.from_dict(app.openapi())
    failures: list[str] = []
    sent = [0]
    with TestClient(app) as client:
        tasks = [client.post("/v1/tasks", json={"target": target, "world": "office"}).json()
                 for target in ("quick", "slow", "ticker")]
        for result in schema.get_all_operations():
            operation = result.ok()
            for mode in MODES:
                try:
                    _fuzz(client, operation.as_strategy(mode), failures, sent, examples)
                except Unsatisfiable:  # nothing to make invalid (e.g. GET /health)
                    assert mode is schemathesis.GenerationMode.NEGATIVE
            for task in tasks if "{task_id}" in operation.path else ():
                strategy = operation.as_strategy(path_parameters={"task_id": task["id"]})
                _fuzz(client, strategy, failures, sent, examples)
    return failures, sent[0]


def _fuzz(
    client: TestClient, strategy: SearchStrategy[Any], failures: list[str], sent: list[int],
    examples: int,
) -> None:
    @given(case=strategy)
    @settings(max_examples=examples, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    def run(case: schemathesis.Case) -> None:
        kwargs = case.as_transport_kwargs(base_url="http://testserver")
        kwargs.pop("cookies", None)
        if isinstance(kwargs.get("data"), str | bytes):
            kwargs["content"] = kwargs.pop("data")
        response = client.request(**kwargs)
        sent[0] += 1
        documented = set(case.operation.definition.raw.get("responses", {}))
        if response.status_code >= 500 or str(response.status_code) not in documented:
            failures.append(f"{case.method} {case.formatted_path} -> {response.status_code} "
                            f"(documented: {sorted(documented)}): {response.text[:300]}\n"
                            f"  {kwargs}")

    run()


def test_no_server_errors_small(make_settings: Callable[..., Settings]) -> None:
    failures, sent = _fuzz_all(make_settings, examples=4)
    assert sent > 50
    assert not failures, "\n".join(failures[:10])


@pytest.mark.slow
def test_no_server_errors_large(make_settings: Callable[..., Settings]) -> None:
    failures, sent = _fuzz_all(make_settings, examples=100)
    assert sent > 1000
    assert not failures, "\n".join(failures[:10])
