"""The pages at / and /tasks/{id}: served from the package, with a strict content policy; the
task's recording file when there is one."""

from __future__ import annotations

import re

from fastapi.testclient import TestClient

from api.pages import STATIC


def test_the_pages_and_their_files_are_served(client: TestClient) -> None:
    for path, marker in (("/", 'id="submit-form"'), ("/tasks/0123abcd", 'id="map"')):
        page = client.get(path)
        assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
        assert marker in page.text
        policy = page.headers["content-security-policy"]
        assert "default-src 'self'" in policy and "unsafe-inline" not in policy
        # every script and style sheet the page names is ours and is served
        for url in re.findall(r'(?:src|href)="(/ui/[^"]+)"', page.text):
            asset = client.get(url)
            assert asset.status_code == 200, url
            assert asset.content == (STATIC / url.removeprefix("/ui/")).read_bytes()
    assert client.get("/ui/task.js").headers["content-type"].startswith(
        ("text/javascript", "application/javascript"))
    assert client.get("/ui/nothing.js").status_code == 404


def test_no_page_loads_anything_from_elsewhere() -> None:
    for path in STATIC.iterdir():
        text = path.read_text(encoding="utf-8")
        assert not re.search(r"(?:src|href)=\"(?:https?:)?//", text), path.name
        assert not re.search(r"fetch\(\s*[\"'`]https?:", text), path.name
        assert "?key=" not in text and "api_key=" not in text  # never in a URL


def test_pages_are_not_in_the_api_schema(client: TestClient) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    assert "/" not in paths and "/tasks/{task_id}" not in paths
    assert "/v1/tasks/{task_id}/recording.rrd" in paths


def test_recording_is_served_when_the_episode_wrote_one(client: TestClient, wait_for) -> None:  # noqa: ANN001
    task = client.post("/v1/tasks", json={"target": "quick", "world": "office"}).json()
    wait_for(client, task["id"], {"succeeded"})
    url = f"/v1/tasks/{task['id']}/recording.rrd"
    assert client.head(url).status_code == 404
    missing = client.get(url)
    assert missing.status_code == 404 and "no recording" in missing.json()["detail"]
    settings = client.app.state.settings
    (settings.tasks_dir / task["id"] / "recording.rrd").write_bytes(b"RRF2fake")
    assert client.head(url).status_code == 200
    got = client.get(url)
    assert got.status_code == 200 and got.content == b"RRF2fake"
    assert got.headers["content-type"] == "application/octet-stream"
    assert client.get("/v1/tasks/nope/recording.rrd").status_code == 404


def test_a_method_a_page_does_not_have_names_the_ones_it_has(client: TestClient) -> None:
    refused = client.post("/")
    assert refused.status_code == 405 and refused.headers["allow"] == "GET, HEAD, OPTIONS"
    assert client.options("/tasks/abc").headers["allow"] == "GET, HEAD, OPTIONS"
