"""The service under an operator, in-process: streams end on shutdown, fair and cancellable
plan jobs, asynchronous plans, local /docs, and the small protocol fixes (empty
Idempotency-Key, 405 Allow, bodies that are not UTF-8, attempts after a requeue, no server
paths in events)."""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Callable

from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app
from api.manager import ClientGoneError, _relative
from tests.api.api_fake_planner import RUNNER as FAKE_PLANNER
from tests.api.test_api_plans import DOMAIN, PROBLEM

Make = Callable[..., Settings]
Wait = Callable[..., dict]
BODY = {"target": "slow", "world": "office"}


def test_docs_are_served_without_a_cdn(client: TestClient) -> None:
    for page in ("/docs", "/redoc"):
        html = client.get(page)
        assert html.status_code == 200
        assert "http://" not in html.text and "https://" not in html.text, html.text
    assert client.get("/docs-assets/swagger-ui-bundle.js").status_code == 200
    assert client.get("/docs-assets/redoc.standalone.js").status_code == 200


def test_empty_idempotency_key_is_refused(client: TestClient) -> None:
    response = client.post("/v1/tasks", json=BODY, headers={"Idempotency-Key": ""})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["header", "idempotency-key"]
    assert client.get("/v1/tasks").json()["count"] == 0


def test_405_and_options_name_every_method(client: TestClient) -> None:
    put = client.put("/v1/tasks/abc")
    assert put.status_code == 405 and put.headers["Allow"] == "DELETE, GET, HEAD, OPTIONS"
    options = client.options("/v1/tasks")
    assert options.status_code == 204 and options.headers["Allow"] == "GET, HEAD, OPTIONS, POST"


def test_body_that_is_not_utf8_is_422(client: TestClient) -> None:
    response = client.post("/v1/tasks", content=b'{"target": "\xff"}',
                           headers={"Content-Type": "application/json"})
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body"]


def test_stream_ends_with_shutdown_event_when_draining(client: TestClient,
                                                       wait_for: Wait) -> None:
    task_id = client.post("/v1/tasks", json=BODY).json()["id"]
    wait_for(client, task_id, {"running"})
    timer = threading.Timer(0.5, client.app.state.draining.set)
    timer.start()
    started = time.monotonic()
    with client.stream("GET", f"/v1/tasks/{task_id}/events") as stream:
        text = "".join(stream.iter_text())
    assert time.monotonic() - started < 15  # not the 30 s the task takes (a loaded machine is slow)
    assert text.rstrip().endswith("retry: 5000") or "event: shutdown" in text
    last = text.split("event: shutdown")[1]
    assert "Last-Event-ID" in last and "\nid:" not in last  # resumable: no id of its own
    assert client.get(f"/v1/tasks/{task_id}").json()["state"] == "running"


def test_requeued_task_marks_its_second_attempt(make_settings: Make, wait_for: Wait) -> None:
    with TestClient(create_app(make_settings())) as client:
        task_id = client.post("/v1/tasks", json=BODY).json()["id"]
        wait_for(client, task_id, {"running"})
    with TestClient(create_app(make_settings(on_restart="requeue"))) as client:
        task = wait_for(client, task_id, {"running"})
        assert task["attempts"] == 2
        client.delete(f"/v1/tasks/{task_id}")
        wait_for(client, task_id, {"cancelled"})
        text = client.get(f"/v1/tasks/{task_id}/events").text.replace(" ", "")
    assert '"state":"running","time"' in text and '"attempt":1' in text
    assert '"attempt":2' in text and "startsagainfromthebeginning" in text


def test_event_paths_are_relative_to_the_task() -> None:
    event = {"type": "plan", "problem": "/srv/data/tasks/abc/timeout-1.pddl", "why": "x"}
    assert _relative(event, "/srv/data/tasks/abc/")["problem"] == "timeout-1.pddl"
    assert _relative(event, "/other/")["problem"] == event["problem"]


def _plan_settings(make_settings: Make, **extra: object) -> Settings:
    values: dict[str, object] = {"plan_workers": 2, "plan_runner": FAKE_PLANNER,
                                 "preload_planner": True, "rate_limit_burst": 1000}
    return make_settings(**{**values, **extra})


def _warm(client: TestClient, workers: int) -> None:
    """One plan per worker at once, so each has spawned and imported the planner."""
    threads = [threading.Thread(target=client.post, args=("/v1/plans",),
                                kwargs={"json": {"domain": DOMAIN, "problem": PROBLEM}})
               for _ in range(workers)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()


def test_short_plan_is_not_blocked_by_a_long_one(make_settings: Make) -> None:
    with TestClient(create_app(_plan_settings(make_settings))) as client:
        _warm(client, 2)
        long = threading.Thread(target=client.post, args=("/v1/plans",),
                                kwargs={"json": {"domain": DOMAIN, "problem": "sleep 120"}})
        long.start()
        time.sleep(0.5)
        short = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM})
        assert short.status_code == 200 and short.json()["status"] == "solved"
        # answered while the 120 s job still runs: it did not wait behind it (no wall-clock
        # threshold, which a loaded machine would break)
        assert long.is_alive()
        client.app.state.manager.jobs.stop()  # end the long one now
        long.join(timeout=10)


def test_disconnected_client_frees_its_worker(make_settings: Make) -> None:
    settings = _plan_settings(make_settings, plan_workers=1, plan_time_limit_s=400)
    with TestClient(create_app(settings)) as client:
        manager = client.app.state.manager
        payload = {"domain_text": DOMAIN, "problem_text": "sleep 300"}
        gone_at = time.monotonic() + 0.5

        async def disconnected() -> bool:
            return time.monotonic() > gone_at

        try:
            client.portal.call(manager.run_job, "plan", payload, disconnected)
        except ClientGoneError:
            pass
        started = time.monotonic()
        quick = {"domain_text": DOMAIN, "problem_text": "sleep 0.1"}
        result = client.portal.call(manager.run_job, "plan", quick)
        assert result.outcome.value == "done"
        # a fresh worker (its start takes seconds, more on a loaded machine), not the end of
        # the 300 s job
        assert time.monotonic() - started < 150


def test_async_plan_job_polls_to_a_result_and_cancels(make_settings: Make) -> None:
    with TestClient(create_app(_plan_settings(make_settings))) as client:
        accepted = client.post("/v1/plans?wait=false", json={"domain": DOMAIN, "problem": PROBLEM})
        assert accepted.status_code == 202 and accepted.headers["Location"].startswith("/v1/plans/")
        job_id = accepted.json()["id"]
        deadline = time.monotonic() + 240  # a hang guard, not a speed test (a loaded machine
        # starts the plan worker slowly)
        while (job := client.get(f"/v1/plans/{job_id}").json())["state"] in ("queued", "running"):
            assert time.monotonic() < deadline
            time.sleep(0.1)
        assert job["state"] == "succeeded" and job["result"]["plan"] == [
            "(go hall kitchen)", "(switch-on kitchen)"]
        bad = client.post("/v1/plans?wait=false", json={"domain": DOMAIN, "problem": "(oops"})
        slow = client.post("/v1/plans?wait=false", json={"domain": DOMAIN, "problem": "sleep 30"})
        cancelled = client.delete(f"/v1/plans/{slow.json()['id']}")
        assert cancelled.status_code == 200 and cancelled.json()["state"] == "cancelled"
        time.sleep(1.5)
        failed = client.get(f"/v1/plans/{bad.json()['id']}").json()
        assert failed["state"] == "failed" and failed["error"]["status"] == 422
        assert client.get("/v1/plans/nope").status_code == 404


def test_run_job_is_cancelled_with_its_coroutine(make_settings: Make) -> None:
    settings = _plan_settings(make_settings, plan_workers=1, plan_time_limit_s=400)
    with TestClient(create_app(settings)) as client:
        manager = client.app.state.manager

        async def give_up() -> None:
            job = asyncio.ensure_future(manager.run_job(
                "plan", {"domain_text": DOMAIN, "problem_text": "sleep 300"}))
            await asyncio.sleep(0.5)
            job.cancel()

        client.portal.call(give_up)
        started = time.monotonic()
        quick = {"domain_text": DOMAIN, "problem_text": "sleep 0.1"}
        assert client.portal.call(manager.run_job, "plan", quick).outcome.value == "done"
        assert time.monotonic() - started < 150  # well before the 300 s job ends
