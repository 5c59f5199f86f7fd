"""Tasks of several objects over HTTP: `targets` with `mode`, `count` and `stop_below` are
accepted and reach the episode runner with their meaning (the echo runner returns the spec it
was given; `EpisodeSpec.from_dict` reads it); every invalid combination is a 422 naming the
field, refused as the runner's own `TaskForm.from_spec` refuses it; a finished task of
several shows each target's part. One real short episode (office, cup and stapler)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from fastapi.testclient import TestClient

from api.config import DEFAULT_TASK_CHECKER, Settings
from api.main import create_app
from api.schemas import MAX_TARGETS, STOP_BELOW, TaskCreate, task_name
from avs_planner.episode.errors import EpisodeError
from avs_planner.harness import tasks
from avs_planner.harness.runner import EpisodeSpec
from avs_planner.harness.tasks import TaskForm

Wait = Callable[..., dict]
# the keys a task of one label had before `targets` existed (its request, and so its spec,
# keeps exactly these)
ONE_LABEL_KEYS = {"target", "category", "world", "world_file", "generate", "robot", "start_room",
                  "start", "seed", "time_budget_s", "strategy", "strategy_options", "qsr",
                  "strict_labels"}
PUBLIC_KEYS = {"id", "state", "request", "created_at", "started_at", "finished_at", "summary",
               "error", "events", "attempts"}

# (body fields, the runner's TaskForm, the request's task-form keys)
ACCEPTED = [
    ({"targets": ["echo", "cup"]}, TaskForm(("echo", "cup")),
     {"targets": ["echo", "cup"], "mode": "all", "count": "one"}),
    ({"targets": ["echo", "cup", "stapler"], "mode": "any"},
     TaskForm(("echo", "cup", "stapler"), mode="any"),
     {"targets": ["echo", "cup", "stapler"], "mode": "any", "count": "one"}),
    ({"target": "echo", "count": "all"}, TaskForm(("echo",), count="all"),
     {"target": "echo", "mode": "all", "count": "all"}),
    ({"targets": ["echo"], "count": "all", "stop_below": 0.05},
     TaskForm(("echo",), count="all", stop_below=0.05),
     {"targets": ["echo"], "mode": "all", "count": "all", "stop_below": 0.05}),
    ({"targets": ["echo"]}, TaskForm(("echo",)),
     {"targets": ["echo"], "mode": "all", "count": "one"}),
]
FORM_KEYS = {"target", "targets", "mode", "count", "stop_below"}


def _spec_form(spec: dict[str, Any]) -> TaskForm:
    """The task form the episode runner reads from the spec it was given."""
    spec = {k: v for k, v in spec.items() if k != "record"}  # the viewer may be missing here
    return EpisodeSpec.from_dict(spec).form


def test_every_form_is_accepted_and_reaches_the_runner_unchanged(client: TestClient,
                                                                 wait_for: Wait) -> None:
    for fields, form, request in ACCEPTED:
        response = client.post("/v1/tasks", json={"world": "office", **fields})
        assert response.status_code == 202, (fields, response.text)
        task = response.json()
        assert {k: v for k, v in task["request"].items() if k in FORM_KEYS} == request
        assert task["task"]["targets"] == list(form.targets)
        assert (task["task"]["mode"], task["task"]["count"]) == (form.mode, form.count)
        assert task["task"]["name"] == form.name and task["task"]["several"] == form.several
        assert task["task"]["stop_below"] == (form.stop_below if form.count == "all" else None)
        done = wait_for(client, task["id"], {"succeeded", "failed"})
        assert done["state"] == "succeeded", done
        spec = done["summary"]["spec"]
        assert {k: v for k, v in spec.items() if k in FORM_KEYS} == request
        assert _spec_form(spec) == form


def test_one_target_keeps_its_request_and_response_shape(client: TestClient,
                                                         wait_for: Wait) -> None:
    response = client.post("/v1/tasks", json={"target": "echo", "world": "office"})
    assert response.status_code == 202
    task = response.json()
    assert set(task["request"]) == ONE_LABEL_KEYS
    assert PUBLIC_KEYS <= set(task) and set(task) - PUBLIC_KEYS == {"task", "targets"}
    assert task["task"] == {"targets": ["echo"], "mode": "all", "count": "one",
                            "stop_below": None, "name": "echo", "several": False}
    done = wait_for(client, task["id"], {"succeeded"})
    assert done["targets"] is None  # one label: the summary's outcome and object say it all
    spec = done["summary"]["spec"]
    assert not FORM_KEYS - {"target"} & set(spec) and spec["target"] == "echo"
    assert EpisodeSpec.from_dict({k: v for k, v in spec.items() if k != "record"}).task is None


def test_a_finished_task_of_several_shows_each_targets_part(client: TestClient,
                                                            wait_for: Wait) -> None:
    body = {"targets": ["parts", "stapler", "book"], "mode": "any", "world": "office"}
    task_id = client.post("/v1/tasks", json=body).json()["id"]
    done = wait_for(client, task_id, {"gave_up", "succeeded", "failed"})
    assert done["state"] == "gave_up", done
    parts = {p["label"]: p for p in done["targets"]}
    assert [p["label"] for p in done["targets"]] == ["parts", "stapler", "book"]
    assert parts["parts"]["outcome"] == "found" and parts["parts"]["objects"][0]["id"] == \
        "object2"
    assert parts["parts"]["objects"][0]["position"] == [1.442, 7.58, 0.893]
    assert parts["stapler"]["outcome"] == "gave_up" and parts["stapler"]["objects"] == []
    assert parts["book"]["outcome"] == "not_needed" and parts["book"]["sim_time_s"] is None
    assert done["summary"]["targets"][0]["sim_time_s"] == parts["parts"]["sim_time_s"] == 58.69
    assert done["task"]["name"] == "parts, stapler or book"
    listed = next(t for t in client.get("/v1/tasks").json()["data"] if t["id"] == task_id)
    assert listed["targets"] == done["targets"] and listed["task"] == done["task"]


# (body fields, the field the 422 names); each is refused by the runner's TaskForm too
REFUSED = [
    ({"target": "cup", "targets": ["book"]}, ["body", "targets"]),
    ({}, ["body", "target"]),
    ({"target": None, "targets": None}, ["body", "target"]),
    ({"targets": []}, ["body", "targets"]),
    ({"targets": "cup"}, ["body", "targets"]),
    ({"targets": ["cup", ""]}, ["body", "targets", 1]),
    ({"targets": ["cup", "cup"]}, ["body", "targets"]),
    ({"targets": [f"label{i}" for i in range(MAX_TARGETS + 1)]}, ["body", "targets"]),
    ({"targets": ["cup", "book"], "mode": "some"}, ["body", "mode"]),
    ({"target": "cup", "count": 3}, ["body", "count"]),
    ({"targets": ["cup", "book"], "count": "all"}, ["body", "count"]),
    ({"target": "cup", "count": "all", "stop_below": 1.5}, ["body", "stop_below"]),
    ({"target": "cup", "count": "all", "stop_below": 0}, ["body", "stop_below"]),
    ({"target": "cup", "count": "all", "stop_below": True}, ["body", "stop_below"]),
    ({"target": "cup", "stop_below": 0.2}, ["body", "stop_below"]),
    ({"targets": ["cup", "book"], "stop_below": 0.2}, ["body", "stop_below"]),
]


@pytest.mark.parametrize(("fields", "loc"), REFUSED)
def test_each_invalid_form_is_422_naming_the_field(client: TestClient, fields: dict,
                                                   loc: list) -> None:
    response = client.post("/v1/tasks", json={"world": "office", **fields})
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert loc in [d["loc"] for d in detail], detail
    assert all(d["msg"] for d in detail)
    with pytest.raises(EpisodeError):  # the runner would refuse it too
        TaskForm.from_spec(fields)
    assert client.get("/v1/tasks").json()["count"] == 0


def test_the_messages_say_what_to_do(client: TestClient) -> None:
    def message(**fields: Any) -> str:
        response = client.post("/v1/tasks", json={"world": "office", **fields})
        return " | ".join(d["msg"] for d in response.json()["detail"])

    assert "not both" in message(target="cup", targets=["book"])
    assert "'target' (one object label) or 'targets'" in message()
    assert "cup more than once" in message(targets=["cup", "book", "cup"])
    assert "one label; 'targets' names 2" in message(targets=["cup", "book"], count="all")
    assert "'count: all' only" in message(target="cup", stop_below=0.2)
    assert f"at most {MAX_TARGETS}" in message(targets=[f"l{i}" for i in range(9)])


def test_the_schema_mirrors_the_runners_task_form() -> None:
    """The limits and names the service states are the runner's, and what the schema accepts
    the runner reads as the same form."""
    assert MAX_TARGETS == tasks.MAX_TARGETS and STOP_BELOW == tasks.STOP_BELOW
    for fields, form, _ in ACCEPTED:
        body = TaskCreate.model_validate({"world": "office", **fields})
        assert TaskForm.from_spec(body.as_request()) == form
        assert task_name(list(form.targets), form.mode, form.count) == form.name
    assert task_name(["cup", "book", "glass"], "any") == "cup, book or glass"
    schema = TaskCreate.model_json_schema()
    (one_target,) = schema["allOf"]
    assert [b["required"] for b in one_target["oneOf"]] == [["target"], ["targets"]]
    assert schema["properties"]["targets"]["anyOf"][0]["maxItems"] == MAX_TARGETS


def test_a_real_episode_of_two_targets(make_settings: Callable[..., Settings],
                                       wait_for: Wait) -> None:
    """The real runner, checker and built-in office world: find a cup and a stapler (7 s
    on the 2-core machine, 5 s of it the episode)."""
    settings = make_settings(episode_runner=Settings.model_fields["episode_runner"].default,
                             worlds_dir=Settings.model_fields["worlds_dir"].default,
                             task_checker=DEFAULT_TASK_CHECKER, record=False)
    with TestClient(create_app(settings)) as client:
        response = client.post("/v1/tasks", json={"targets": ["cup", "stapler"],
                                                  "world": "office", "seed": 0})
        assert response.status_code == 202, response.text
        done = wait_for(client, response.json()["id"], {"succeeded", "gave_up", "timeout",
                                                        "failed"}, timeout=240)
    assert done["state"] == "succeeded", done.get("error") or done["summary"]
    assert done["summary"]["target"] == done["task"]["name"] == "cup and stapler"
    assert done["summary"]["task"] == {"targets": ["cup", "stapler"], "mode": "all",
                                       "count": "one"}
    parts = {p["label"]: p for p in done["targets"]}
    assert set(parts) == {"cup", "stapler"}
    for label, part in parts.items():
        assert part["outcome"] == "found" and part["correct"]
        assert [o["label"] for o in part["objects"]] == [label]
        assert 0 < part["sim_time_s"] <= done["summary"]["sim_time_s"]
