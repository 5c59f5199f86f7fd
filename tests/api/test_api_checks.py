"""Task input is checked at submission: each wrong field is a 422 naming it, against the
real knowledge base, built-in worlds and strategy registry."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from api.config import DEFAULT_TASK_CHECKER, Settings
from api.main import create_app

Make = Callable[..., Settings]
GOOD = {"target": "cerealbox", "category": "kitchen", "world": "office"}
PR2_WORLD = """name: tiny
size: [6.0, 4.0]
rooms:
  - {name: lab, category: office, rect: [0, 0, 6, 4]}
robot: {model: pr2, start: [1.0, 1.0, 0.0]}
"""


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[TestClient]:
    data = tmp_path_factory.mktemp("checks")
    settings = Settings(data_dir=data, api_key=None, workers=1, plan_workers=1, queue_size=100,
                        task_checker=DEFAULT_TASK_CHECKER, preload_planner=False,
                        warm_workers=False, rate_limit_burst=1000,
                        episode_runner="tests/api/api_fake_runner.py:run")
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def _loc(client: TestClient, **fields: Any) -> list[list[Any]]:
    response = client.post("/v1/tasks", json={**GOOD, **fields})
    assert response.status_code == 422, response.text
    return [error["loc"] for error in response.json()["detail"]]


@pytest.mark.parametrize(("fields", "loc"), [
    ({"target": "unicorn", "strict_labels": True}, ["body", "target"]),
    ({"category": "attic"}, ["body", "category"]),
    ({"start_room": "ballroom"}, ["body", "start_room"]),
    ({"start": [100.0, 100.0, 0.0]}, ["body", "start"]),  # off the map
    ({"start": [2.0, 6.0, 0.0]}, ["body", "start"]),  # inside table1
    ({"strategy": "teleport"}, ["body", "strategy"]),
    ({"strategy_options": {"bogus": 1}}, ["body", "strategy_options"]),
    ({"strategy_options": {"max_steps": "many"}}, ["body", "strategy_options"]),
    ({"world": "atlantis"}, ["body", "world"]),
])
def test_each_bad_field_is_422_naming_it(client: TestClient, fields: dict, loc: list) -> None:
    assert loc in _loc(client, **fields)


def test_non_finite_start_is_422_not_stored_as_null(client: TestClient) -> None:
    body = b'{"target": "cerealbox", "world": "office", "start": [NaN, 1.0, 0.0]}'
    response = client.post("/v1/tasks", content=body,
                           headers={"Content-Type": "application/json"})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "start", 0]
    inf = client.post("/v1/tasks", content=body.replace(b"NaN", b"Infinity"),
                      headers={"Content-Type": "application/json"})
    assert inf.status_code == 422


def test_every_problem_is_reported_at_once(client: TestClient) -> None:
    locs = _loc(client, target="unicorn", category="attic", start_room="ballroom",
                strict_labels=True)
    assert {"target", "category", "start_room"} <= {loc[-1] for loc in locs}


def test_an_unknown_label_is_searched_for_unless_strict(client: TestClient) -> None:
    """Without `strict_labels` the episode searches for a label the knowledge base lacks
    (with an uninformed prior); the flag reaches the episode only when set."""
    accepted = client.post("/v1/tasks", json={**GOOD, "target": "unicorn"})
    assert accepted.status_code == 202, accepted.text
    assert accepted.json()["request"]["strict_labels"] is False
    strict = client.post("/v1/tasks", json={**GOOD, "target": "unicorn", "strict_labels": True})
    assert strict.status_code == 422
    assert "unknown object label 'unicorn'" in strict.json()["detail"][0]["msg"]
    still = client.post("/v1/tasks", json={**GOOD, "target": "unicorn", "category": "attic"})
    assert [d["loc"] for d in still.json()["detail"]] == [["body", "category"]]


def test_every_label_of_targets_is_checked(client: TestClient) -> None:
    """The knowledge check covers each label of a task of several: labels the knowledge
    base lacks (only with `strict_labels`; one item each, at `targets`), two spellings of one
    label, and the room category, as for `target`."""
    body = {**GOOD, "target": None, "targets": ["cerealbox", "unicorn", "griffin"]}
    strict = client.post("/v1/tasks", json={**body, "strict_labels": True})
    assert strict.status_code == 422, strict.text
    detail = strict.json()["detail"]
    assert [d["loc"] for d in detail] == [["body", "targets"], ["body", "targets"]]
    assert "'unicorn'" in detail[0]["msg"] and "'griffin'" in detail[1]["msg"]
    accepted = client.post("/v1/tasks", json={**body, "mode": "any"})
    assert accepted.status_code == 202, accepted.text
    assert accepted.json()["request"]["targets"] == ["cerealbox", "unicorn", "griffin"]
    twice = client.post("/v1/tasks", json={**body, "targets": ["cup", "Cup"]})
    assert twice.status_code == 422
    (error,) = twice.json()["detail"]
    assert error["loc"] == ["body", "targets"] and "spelled differently" in error["msg"]
    assert ["body", "category"] in _loc(client, target=None, targets=["cup", "stapler"],
                                        category="attic")
    assert ["body", "target"] in _loc(client, target="unicorn", count="all",
                                      strict_labels=True)


def test_inline_world_is_checked_too(client: TestClient) -> None:
    body = {"target": "cerealbox", "world_file": "name: x\nsize: [1, 1]\n"}
    response = client.post("/v1/tasks", json=body)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == [
        "body", "world_file"]


def test_good_task_is_accepted_and_keeps_the_worlds_robot(client: TestClient) -> None:
    accepted = client.post("/v1/tasks", json={**GOOD, "strategy": "exhaustive",
                                              "strategy_options": {"headings": 4}})
    assert accepted.status_code == 202, accepted.text
    assert accepted.json()["request"]["robot"] is None  # the episode takes the world's robot
    inline = client.post("/v1/tasks", json={"target": "cup", "world_file": PR2_WORLD,
                                            "start": [3.0, 2.0, 0.0]})
    assert inline.status_code == 202, inline.text
    assert inline.json()["request"]["robot"] is None


def test_strategies_are_listed(client: TestClient) -> None:
    names = [s["name"] for s in client.get("/v1/strategies").json()["data"]]
    assert "switching" in names and "exhaustive" in names


def test_default_robot_comes_from_the_world_file(tmp_path: Path) -> None:
    from avs_planner.harness.runner import EpisodeSpec
    from avs_planner.harness.sim_robot import load_spec

    world = tmp_path / "tiny.yaml"
    world.write_text(PR2_WORLD)
    spec = EpisodeSpec.from_dict({"target": "cup", "world": str(world), "robot": None})
    assert load_spec(spec.world, spec.robot).robot.model == "pr2"


CUP_RIGHT = {"target": "cup", "relations": ["right", "close"], "of": "keyboard", "count": 2}


@pytest.mark.parametrize(("qsr", "names"), [
    ([{**CUP_RIGHT, "of": "sofa"}], "descriptions[0].of: unknown landmark label 'sofa'"),
    ([CUP_RIGHT, {**CUP_RIGHT, "relations": ["up"]}], "descriptions[1].relations"),
    ([{**CUP_RIGHT, "count": -1}], "descriptions[0].count: must be > 0"),
    ([{"target": "cup", "of": "keyboard"}], "descriptions[0]: missing key(s) count"),
    ([], "non-empty list"),
    ({"descriptions": [{**CUP_RIGHT, "via": [{"relations": ["front"], "of": "lamp"}]}]},
     "descriptions[0].via[0].of"),
])
def test_bad_qsr_descriptions_are_422_naming_the_entry(client: TestClient, qsr: Any,
                                                       names: str) -> None:
    response = client.post("/v1/tasks", json={**GOOD, "target": "cup", "strategy": "qsr",
                                              "qsr": qsr})
    assert response.status_code == 422, response.text
    [error] = [e for e in response.json()["detail"] if e["loc"] == ["body", "qsr"]]
    assert names in error["msg"]


def test_a_qsr_field_of_the_wrong_shape_is_422_not_500(client: TestClient) -> None:
    for qsr in ("cup right of keyboard", 3, [1, 2]):
        response = client.post("/v1/tasks", json={**GOOD, "target": "cup", "qsr": qsr})
        assert response.status_code == 422, response.text
        assert all(e["loc"][:2] == ["body", "qsr"] for e in response.json()["detail"])


def test_a_task_with_qsr_descriptions_is_accepted_and_reaches_the_episode(
        client: TestClient) -> None:
    from avs_planner.harness.runner import EpisodeSpec

    for qsr in ([CUP_RIGHT], {"descriptions": [CUP_RIGHT]}):
        accepted = client.post("/v1/tasks", json={"target": "cup", "world": "qsr_desks_a",
                                                  "strategy": "qsr", "qsr": qsr})
        assert accepted.status_code == 202, accepted.text
        request = accepted.json()["request"]
        assert request["qsr"] == qsr
        spec = EpisodeSpec.from_dict({**request, "task_id": "t", "output_dir": None})
        [description] = spec.qsr.descriptions_for("cup")
        assert description.text() == "right(cup, keyboard) & close(cup, keyboard)"
        assert description.count == 2


def test_a_generated_building_is_accepted_and_reaches_the_episode(client: TestClient) -> None:
    from avs_planner.harness.runner import EpisodeSpec

    accepted = client.post("/v1/tasks", json={"target": "stapler", "robot": "pr2",
                                              "generate": {"seed": 3, "style": "lab"}})
    assert accepted.status_code == 202, accepted.text
    request = accepted.json()["request"]
    assert request["generate"] == {"seed": 3, "style": "lab", "rooms": None, "surprise": 0.25}
    spec = EpisodeSpec.from_dict({**request, "task_id": "t", "output_dir": None})
    assert spec.generate["seed"] == 3 and spec.robot == "pr2"


@pytest.mark.parametrize(("generate", "loc", "names"), [
    ({"seed": 3, "rooms": 40}, ["body", "generate"], "rooms: style office takes 3 to 12"),
    ({"seed": 3, "style": "castle"}, ["body", "generate", "style"], "office"),
    ({"seed": -1}, ["body", "generate", "seed"], "greater than or equal to 0"),
    ({"style": "lab"}, ["body", "generate", "seed"], "required"),
    ({"seed": 3, "floors": 2}, ["body", "generate", "floors"], "not permitted"),
])
def test_a_bad_generated_building_is_422_naming_it(client: TestClient, generate: dict,
                                                   loc: list, names: str) -> None:
    response = client.post("/v1/tasks", json={"target": "stapler", "generate": generate})
    assert response.status_code == 422, response.text
    [error] = [e for e in response.json()["detail"] if e["loc"] == loc]
    assert names in error["msg"]


def test_a_generated_building_is_checked_like_any_world(client: TestClient) -> None:
    """Its start room and start pose are checked against the generated plan; two worlds at
    once are refused."""
    locs = _loc(client, world=None, generate={"seed": 3}, start_room="ballroom")
    assert ["body", "start_room"] in locs
    both = client.post("/v1/tasks", json={**GOOD, "generate": {"seed": 3}})
    assert both.status_code == 422 and "exactly one of" in both.text
