"""The task page's targets card (api/static/targets.js): each target's outcome, its objects
and time, rendered to HTML by Node with a minimal DOM (the page's own `AVS.el`), from a
summary's `targets` and from the `task`, `turn` and `target` events of a running task.
Skipped without Node; the browser tests open a real page."""

from __future__ import annotations

import re

from api.pages import STATIC
from tests.api.pages_node import needs_node, run_js

pytestmark = needs_node

SUMMARY_TARGETS = [
    {"label": "cup", "outcome": "found", "reason": "cup at (1.44, 7.58, 0.89) in room1",
     "objects": [{"id": "object2", "label": "cup", "position": [1.442, 7.58, 0.893],
                  "room": "room1", "truth": "cup1", "correct": True},
                 {"id": "object9", "label": "cup", "position": [3.0, 1.25, 0.8],
                  "room": "room4", "truth": None, "correct": False}],
     "sim_time_s": 58.69, "turns": 1, "instances": 2, "distinct": 1, "correct": False},
    {"label": "book", "outcome": "gave_up", "reason": "no plan reaches the threshold",
     "objects": [], "sim_time_s": 208.3, "turns": 2, "instances": 0, "distinct": 0,
     "correct": True},
    {"label": "glass", "outcome": "timeout", "reason": "simulated time budget 600 s spent",
     "objects": [], "sim_time_s": 600.0, "turns": 1},
    {"label": "stapler", "outcome": "not_needed", "reason": "", "objects": [],
     "sim_time_s": None, "turns": 0},
]




def _rows(html: str) -> dict[str, str]:
    return dict(re.findall(r'<tr data-label="([^"]+)"[^>]*>(.*?)</tr>', html))


def test_each_targets_outcome_objects_and_time_from_the_summary() -> None:
    html = run_js("(parts) => AVS_TARGETS.table(parts).html", SUMMARY_TARGETS)
    assert html.startswith('<table class="targets">')
    assert re.findall(r"<th>(\w+)</th>", html) == ["target", "outcome", "objects", "time",
                                                   "turns"]
    rows = _rows(html)
    assert list(rows) == ["cup", "book", "glass", "stapler"]
    cup = rows["cup"]
    assert '<span class="state state-succeeded" title="cup at (1.44, 7.58, 0.89) in room1">' \
        'found</span>' in cup
    assert "<li>object2 at (1.44, 7.58) in room1</li>" in cup
    assert "<li>object9 at (3.00, 1.25) in room4 (not a true cup)</li>" in cup
    assert '<td class="num">58.7 s</td><td class="num">1</td>' in cup
    assert "why" not in cup  # where it was found is in its objects
    assert "state-gave_up" in rows["book"] and ">gave up</span>" in rows["book"]
    assert '<div class="why muted">no plan reaches the threshold</div>' in rows["book"]
    assert '<span class="muted">none</span>' in rows["book"] and "208.3 s" in rows["book"]
    assert ">timeout</span>" in rows["glass"] and "600.0 s" in rows["glass"]
    assert ">not needed</span>" in rows["stapler"] and "why" not in rows["stapler"]
    assert '<td class="num"></td><td class="num">0</td>' in rows["stapler"]
    assert 'data-outcome="not_needed"' in html


def test_a_count_says_why_it_stopped() -> None:
    part = {"label": "cup", "outcome": "found", "objects": [], "sim_time_s": 90.0, "turns": 3,
            "reason": "2 found; P(another cup in space not yet searched) = 0.06 < 0.1"}
    html = run_js("(part) => AVS_TARGETS.table([part], {count: 'all'}).html", part)
    assert '<div class="why muted">2 found; P(another cup' in html


def test_a_running_task_is_followed_from_its_events() -> None:
    """`task` opens every label; `turn` starts count; a `target` event ends a label's part,
    its objects placed where the map's known objects are, its time from the task's start."""
    script = """(events) => {
      const parts = AVS_TARGETS.open(events[0].targets);
      const objects = [["object7", "stapler", 8.837, 0.592, "room3"]];
      for (const e of events.slice(1)) AVS_TARGETS.apply(parts, e, objects, events[0].t);
      return AVS_TARGETS.table(parts).html;
    }"""
    events = [
        {"type": "task", "t": 10.0, "targets": ["cup", "stapler"], "mode": "all"},
        {"type": "turn", "t": 10.0, "target": "stapler", "status": "start", "watch": ["cup"]},
        {"type": "target", "t": 70.5, "target": "stapler", "outcome": "found",
         "reason": "stapler at (8.84, 0.59, 0.85) in room3", "found": ["object7"]},
        {"type": "turn", "t": 70.5, "target": "cup", "status": "start", "watch": []},
    ]
    rows = _rows(run_js(script, events))
    assert ">found</span>" in rows["stapler"]
    assert "<li>object7 at (8.84, 0.59) in room3</li>" in rows["stapler"]
    assert '<td class="num">60.5 s</td><td class="num">1</td>' in rows["stapler"]
    assert "state-running" in rows["cup"] and ">searching</span>" in rows["cup"]
    assert '<td class="num"></td><td class="num">1</td>' in rows["cup"]


def test_the_forms_read_as_words() -> None:
    script = "(forms) => forms.map((f) => AVS_TARGETS.formText(f)).join(' | ')"
    forms = [{"mode": "all", "count": "one"}, {"mode": "any", "count": "one"},
             {"mode": "all", "count": "all", "stop_below": 0.05}]
    assert run_js(script, forms) == ("one of each | the first of any of them | every instance, "
                                    "until P(another) < 0.05")


def test_the_task_page_has_the_targets_card_and_its_script() -> None:
    page = (STATIC / "task.html").read_text(encoding="utf-8")
    assert '<section class="card" id="targets-card" hidden>' in page
    scripts = re.findall(r'<script src="/ui/([^"]+)"', page)
    assert scripts == ["common.js", "targets.js", "memory.js", "task.js"]  # before task.js
    form = (STATIC / "index.html").read_text(encoding="utf-8")
    for field in ('id="f-mode"', 'id="f-count"', 'id="f-stop"'):
        assert field in form
