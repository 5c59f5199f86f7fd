"""GET /v1/tasks/{id}/explanation: the episode's assumption ledger, once the task has ended."""

from __future__ import annotations

from collections.abc import Callable

from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app

Wait = Callable[..., dict]


def test_explanation_of_an_ended_task(client: TestClient, wait_for: Wait) -> None:
    task = client.post("/v1/tasks", json={"target": "explained", "world": "office"}).json()
    assert wait_for(client, task["id"], {"gave_up", "failed"})["state"] == "gave_up"
    response = client.get(f"/v1/tasks/{task['id']}/explanation")
    assert response.status_code == 200, response.text
    explanation = response.json()
    assert explanation["outcome"] == "gave_up"
    (entry,) = explanation["assumptions"]
    assert entry["status"] == "refuted" and entry["p_first"] == 0.3
    assert "placeholder3 was explored" in entry["reason"]
    (hypothesis,) = explanation["give_up"]["hypotheses"]
    assert hypothesis["hypothesis"] == "a kitchen lies behind placeholder3"


def test_no_explanation_is_a_404_that_says_why(client: TestClient, wait_for: Wait) -> None:
    unknown = client.get("/v1/tasks/nosuchtask/explanation")
    assert unknown.status_code == 404 and "no task with id nosuchtask" in unknown.json()["detail"]
    running = client.post("/v1/tasks", json={"target": "slow", "world": "office"}).json()
    wait_for(client, running["id"], {"running"})
    response = client.get(f"/v1/tasks/{running['id']}/explanation")
    assert response.status_code == 404
    assert "no explanation yet: it is running" in response.json()["detail"]
    client.delete(f"/v1/tasks/{running['id']}")
    quick = client.post("/v1/tasks", json={"target": "quick", "world": "office"}).json()
    wait_for(client, quick["id"], {"succeeded"})
    response = client.get(f"/v1/tasks/{quick['id']}/explanation")
    assert response.status_code == 404 and "left no trace" in response.json()["detail"]


def test_reading_an_explanation_needs_the_key_like_every_read(
        make_settings: Callable[..., Settings], wait_for: Wait) -> None:
    app = create_app(make_settings(api_key="s3cret"))
    with TestClient(app, headers={"X-API-Key": "s3cret"}) as client:
        task = client.post("/v1/tasks", json={"target": "explained", "world": "office"}).json()
        wait_for(client, task["id"], {"gave_up", "failed"})
        assert client.get(f"/v1/tasks/{task['id']}/explanation").status_code == 200
        anonymous = client.get(f"/v1/tasks/{task['id']}/explanation", headers={"X-API-Key": ""})
        assert anonymous.status_code == 401


def test_the_recording_of_an_ended_task(make_settings: Callable[..., Settings],
                                        wait_for: Wait) -> None:
    with TestClient(create_app(make_settings(record=True))) as client:
        task = client.post("/v1/tasks", json={"target": "explained", "world": "office"}).json()
        wait_for(client, task["id"], {"gave_up", "failed"})
        response = client.get(f"/v1/tasks/{task['id']}/recording.rrd")
        assert response.status_code == 200 and response.content.startswith(b"RRF2")
    with TestClient(create_app(make_settings(record=False))) as client:
        task = client.post("/v1/tasks", json={"target": "explained", "world": "office"}).json()
        wait_for(client, task["id"], {"gave_up", "failed"})
        response = client.get(f"/v1/tasks/{task['id']}/recording.rrd")
        assert response.status_code == 404
        assert "does not record episodes" in response.json()["detail"]


def test_recording_needs_no_address_space_limit(make_settings: Callable[..., Settings]) -> None:
    """The Rerun recorder reserves more address space than the worker's limit allows (the
    worker died on every recorded task): recording is refused with a limit, and off by
    default when one is set."""
    import pydantic
    import pytest

    with pytest.raises(pydantic.ValidationError, match="AVS_MEMORY_LIMIT_MB=0"):
        make_settings(record=True, memory_limit_mb=2048)
    assert not make_settings(memory_limit_mb=2048).records()
