"""What a task took from its building's memory, on the task page (api/static/memory.js): the
trace's `memory` events in a line each and the summary's `memory` and `experience` parts as
rows, rendered by Node with the minimal DOM of the targets card's tests; and the buildings
pages are served. Skipped without Node where Node is needed."""

from __future__ import annotations

import json
import re

from fastapi.testclient import TestClient

from tests.api.pages_node import needs_node, run_js


@needs_node
def test_memory_events_in_a_line_each() -> None:
    events = [
        {"type": "memory", "recalled": True, "tasks": 2, "places": 14, "rooms": 4,
         "furniture": 6, "sightings": [{"label": "cup"}, {"label": "book"}], "faded": 1},
        {"type": "memory", "checked": "cerealbox", "position": [2.21, 5.89, 0.87],
         "weight": 0.992, "seen": False, "dropped": True},
        {"type": "memory", "checked": "cup", "position": [1.0, 7.5, 0.9], "weight": 0.8,
         "seen": True, "object": "object3"},
        {"type": "memory", "unreachable": "book", "position": [9.0, 1.0, 0.8]},
    ]
    lines = json.loads(run_js("(es) => JSON.stringify(es.map(AVS_MEMORY.describe))", events))
    assert lines == [
        "recalled 2 task(s) before: 14 places, 4 rooms, 6 furniture, 2 sighting(s), 1 faded",
        "checked cerealbox at (2.21, 5.89, 0.87) (P in place 0.992): not there, dropped",
        "checked cup at (1, 7.5, 0.9) (P in place 0.8): seen again as object3",
        "book at (9, 1, 0.8): no way to look, kept for later",
    ]


@needs_node
def test_the_summary_s_memory_and_experience_parts_as_rows() -> None:
    part = {"tasks_before": 1, "building_clock_s": 651.5, "furniture": 6, "sightings": 2,
            "checked": 1, "confirmed": 0, "saved": True}
    html = run_js("(p) => { const dl = AVS.el('dl'); AVS_MEMORY.rows(dl, "
                 "AVS_MEMORY.summaryRows(p.memory).concat(AVS_MEMORY.experienceRows("
                 "p.experience))); return dl.html; }",
                 {"memory": part, "experience": {"store": "experience.sqlite3",
                                                 "building": "office-1", "updated": True}})
    pairs = re.findall(r"<dt>([^<]+)</dt><dd>([^<]*)</dd>", html)
    assert pairs == [("tasks before", "1"), ("building clock", "651.5 s"), ("furniture", "6"),
                     ("sightings", "2"), ("checked", "1"), ("confirmed", "0"),
                     ("saved", "true"), ("store", "experience.sqlite3"),
                     ("building", "office-1"), ("updated", "true")]


def test_the_buildings_pages_are_served(client: TestClient) -> None:
    for path in ("/buildings", "/buildings/office-3"):
        page = client.get(path)
        assert page.status_code == 200 and 'id="buildings"' in page.text
        assert "default-src 'self'" in page.headers["content-security-policy"]
        for url in re.findall(r'(?:src|href)="(/ui/[^"]+)"', page.text):
            assert client.get(url).status_code == 200, url
    task_page = client.get("/tasks/0123abcd").text
    assert 'id="memory-card"' in task_page and "/ui/memory.js" in task_page
    assert 'href="/buildings"' in client.get("/").text
    paths = client.get("/openapi.json").json()["paths"]
    assert "/buildings" not in paths and "/v1/buildings/{building_id}" in paths
