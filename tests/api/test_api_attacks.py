"""The service under attack: no file path from a request reaches the
file system, and a small request cannot buy unbounded work or an unbounded answer."""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from pydantic import BaseModel

from api.config import Settings
from api.limits import MAX_YAML_ALIASES, names_a_file
from api.main import create_app
from api.schemas import DomainCheckCreate, GeneratedWorld, PlanCreate, TaskCreate
from avs_planner.strategies import STRATEGIES

Make = Callable[..., Settings]
BODY = {"target": "quick", "world": "office"}


def alias_bomb(levels: int = 8, width: int = 10) -> str:
    """The YAML of the report: each level a list of `width` aliases of the level below, so
    the last expands to width**levels scalars."""
    lines = [f"l0: &l0 [{', '.join(['lol'] * width)}]"]
    for level in range(1, levels):
        lines.append(f"l{level}: &l{level} [{', '.join([f'*l{level - 1}'] * width)}]")
    return "\n".join(lines) + "\n"


@pytest.fixture
def client(make_settings: Make) -> Iterator[TestClient]:
    """An open service with room for many calls (the option walk makes hundreds)."""
    settings = make_settings(rate_limit_per_minute=1e6, rate_limit_burst=10**6, queue_size=100)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


# -- 1. no file path from a request ---------------------------------------------------------

class _FileWatch:
    """Records every file system call (audit events) in this process that names `root`."""

    EVENTS = ("open", "os.listdir", "os.scandir", "os.mkdir", "os.rename", "os.remove",
              "shutil.copyfile", "os.chmod", "os.truncate")

    def __init__(self, root: Path):
        self.root = str(root)
        self.seen: list[tuple[str, str]] = []
        self.active = False

    def __call__(self, event: str, args: tuple[Any, ...]) -> None:
        if self.active and event in self.EVENTS and args and self.root in str(args[0]):
            self.seen.append((event, str(args[0])))


_WATCH: _FileWatch | None = None


@pytest.fixture
def file_watch(tmp_path: Path) -> Iterator[_FileWatch]:
    """An audit hook (which cannot be removed: it is made inert after the test) watching a
    folder holding a file a request might name."""
    global _WATCH
    root = tmp_path / "secret"
    root.mkdir()
    (root / "world.yaml").write_text("name: secret\nsize: [2, 2]\nrooms: []\n")
    if _WATCH is None:
        _WATCH = _FileWatch(root)
        sys.addaudithook(lambda event, args: _WATCH(event, args) if _WATCH else None)
    _WATCH.root, _WATCH.seen, _WATCH.active = str(root), [], True
    try:
        yield _WATCH
    finally:
        _WATCH.active = False


def test_learn_file_is_refused_naming_the_option(client: TestClient, tmp_path: Path) -> None:
    target = tmp_path / "x.yaml"
    for value in (str(target), "notes", "../../avs.sqlite3"):
        response = client.post("/v1/tasks", json={**BODY, "strategy": "qsr",
                                                  "strategy_options": {"learn_file": value}})
        assert response.status_code == 422, response.text
        detail = response.json()["detail"]
        assert detail[0]["loc"] == ["body", "strategy_options", "learn_file"]
        assert "names a file" in detail[0]["msg"]
    assert not target.exists()
    # an empty one names no file: the service drops options naming files before a task
    # runs (the strategies no longer take it: learned QSR counts live in the experience
    # store, which only the CLI names)
    empty = client.post("/v1/tasks", json={**BODY, "strategy": "qsr",
                                           "strategy_options": {"learn_file": ""}})
    assert empty.status_code == 202


def test_every_option_of_every_strategy_refuses_a_path(client: TestClient,
                                                      file_watch: _FileWatch) -> None:
    """Whatever the option, a value naming a file is a 422 naming the option; an option whose
    name says it names a file is refused whatever its value."""
    path = f"{file_watch.root}/world.yaml"
    file_options = set()
    for strategy in STRATEGIES.values():
        for option in strategy.options:
            values: list[Any] = [path, "~/x", "..", "out.json"]
            if names_a_file(option):
                file_options.add(option)
                values.append("plain")
            for value in values:
                response = client.post("/v1/tasks", json={
                    **BODY, "strategy": strategy.name, "strategy_options": {option: value}})
                assert response.status_code == 422, (strategy.name, option, value)
                locs = [d["loc"] for d in response.json()["detail"]]
                assert ["body", "strategy_options", option] in locs, (option, locs)
    assert "learn_file" not in file_options  # removed: the experience store replaces it
    assert file_watch.seen == []


def _string_fields(model: type[BaseModel]) -> dict[str, dict[str, Any]]:
    """Every property of the model's JSON schema that may hold a string (directly, in a
    union, in a list or in a nested object), by dotted name."""
    schema = model.model_json_schema()
    defs = schema.get("$defs", {})
    found: dict[str, dict[str, Any]] = {}

    def walk(node: dict[str, Any], name: str) -> None:
        if "$ref" in node:
            walk(defs[node["$ref"].rsplit("/", 1)[1]], name)
            return
        for key in ("anyOf", "oneOf", "allOf"):
            for option in node.get(key, []):
                walk(option, name)
        if node.get("type") == "string":
            found[name] = node
        if node.get("type") == "array":
            items = node.get("items") or {}
            walk(items, name + "[]") if isinstance(items, dict) else None
            for i, item in enumerate(node.get("prefixItems", [])):
                walk(item, f"{name}[{i}]")
        for prop, sub in (node.get("properties") or {}).items():
            walk(sub, f"{name}.{prop}" if name else prop)
        extra = node.get("additionalProperties")
        if isinstance(extra, dict):
            walk(extra, f"{name}.*")

    walk(schema, "")
    return found


# how each string field of a request is kept off the file system; a new field fails the test
# until it is classified here
_NAMES = "a name pattern without '/' (looked up among known names, never a path)"
_INLINE = "inline text, parsed as text (never opened)"
_CLOSED = "one of a closed set of values"
_CHECKED = "refused when it looks like a path (strategy options, qsr)"
_FOLDER = ("an id pattern without '/', starting with a letter or digit (so never '.' or "
           "'..'): one folder the service builds under DATA_DIR/buildings")
TASK_FIELDS = {
    "target": _NAMES, "targets[]": _NAMES, "category": _NAMES, "world": _NAMES,
    "start_room": _NAMES, "strategy": _NAMES, "world_file": _INLINE, "robot": _CLOSED,
    "mode": _CLOSED, "count": _CLOSED, "generate.style": _CLOSED,
    "strategy_options.*": _CHECKED, "qsr[].*": _CHECKED, "qsr.*": _CHECKED,
    "building": _FOLDER,
}
PLAN_FIELDS = {"domain": _INLINE, "problem": _INLINE, "problems[]": _INLINE}


def test_every_string_field_of_every_request_is_classified() -> None:
    fields = {**_string_fields(TaskCreate), **_string_fields(PlanCreate),
              **_string_fields(DomainCheckCreate)}
    assert set(fields) <= {*TASK_FIELDS, *PLAN_FIELDS}, set(fields) - {*TASK_FIELDS,
                                                                      *PLAN_FIELDS}
    assert {"style"} == set(_string_fields(GeneratedWorld))
    for name, how in TASK_FIELDS.items():
        if how is _NAMES:
            assert "/" not in fields[name]["pattern"] and fields[name]["pattern"].startswith("^")
        if how is _CLOSED:
            assert "enum" in fields[name] or "const" in fields[name], name
        if how is _FOLDER:
            pattern = fields[name]["pattern"]
            assert "/" not in pattern and pattern.startswith("^[A-Za-z0-9]"), name


def test_a_path_in_any_task_field_is_refused(client: TestClient, file_watch: _FileWatch) -> None:
    path = f"{file_watch.root}/world.yaml"
    bodies: dict[str, dict[str, Any]] = {
        "target": {"target": path, "world": "office"},
        "targets[]": {"targets": ["cup", path], "world": "office"},
        "mode": {"targets": ["cup", "book"], "mode": path, "world": "office"},
        "count": {**BODY, "count": path},
        "category": {**BODY, "category": path},
        "world": {"target": "quick", "world": path},
        "start_room": {**BODY, "start_room": path},
        "strategy": {**BODY, "strategy": path},
        "world_file": {"target": "quick", "world_file": path},
        "robot": {**BODY, "robot": path},
        "generate.style": {"target": "quick", "generate": {"seed": 1, "style": path}},
        "strategy_options.*": {**BODY, "strategy_options": {"views": path}},
        "qsr[].*": {**BODY, "qsr": [{"target": "cup", "relations": ["right"], "of": path}]},
        "qsr.*": {**BODY, "qsr": {"descriptions": path}},
        "building": {**BODY, "building": path},
    }
    assert set(bodies) == set(TASK_FIELDS)
    for name, body in bodies.items():
        response = client.post("/v1/tasks", json=body)
        assert response.status_code == 422, (name, response.text)
    assert file_watch.seen == []


def test_pddl_bodies_reach_the_planner_as_text_only(client: TestClient,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    import inspect

    from api.workers import JobOutcome, JobResult
    from avs_planner import jobs

    sent: list[dict[str, Any]] = []

    async def run_job(kind: str, payload: dict[str, Any], *args: Any, **kwargs: Any) -> Any:
        sent.append(payload)
        value = ({"status": "unsolvable", "plan": []} if kind == "plan" else [])
        return JobResult(JobOutcome.DONE, value=value)

    monkeypatch.setattr(client.app.state.manager, "run_job", run_job)
    assert client.post("/v1/plans", json={"domain": "/etc/passwd",
                                          "problem": "/etc/hosts"}).status_code == 200
    assert client.post("/v1/domains/check", json={"domain": "/etc/passwd",
                                                  "problems": ["/x"]}).status_code == 200
    assert set(sent[0]) == {"domain_text", "problem_text", "options"}
    assert set(sent[1]) == {"domain_text", "problem_texts"}
    assert set(inspect.signature(jobs.plan).parameters) >= {"domain_text", "problem_text"}
    assert set(inspect.signature(jobs.check_domain).parameters) >= {"domain_text",
                                                                     "problem_texts"}


def test_a_stored_task_with_a_file_option_runs_without_it(client: TestClient,
                                                         wait_for: Callable[..., dict]) -> None:
    """Tasks stored before the service refused file options (or written to the store by
    hand) reach the runner without them; `strict_labels` always reaches it."""
    manager = client.app.state.manager
    request = {**BODY, "target": "echo", "strategy": "qsr", "strict_labels": True,
               "strategy_options": {"learn_file": "/tmp/avs-should-not-exist.yaml",
                                    "abort_s": 5.0}}
    manager.store.insert("old0task", request, "host:testclient")
    manager._enqueue("old0task")
    spec = wait_for(client, "old0task", {"succeeded"})["summary"]["spec"]
    assert spec["strategy_options"] == {"abort_s": 5.0}
    assert spec["strict_labels"] is True
    plain = client.post("/v1/tasks", json={**BODY, "target": "echo"}).json()
    assert wait_for(client, plain["id"], {"succeeded"})["summary"]["spec"]["strict_labels"] is False


# -- 2. bounded parsing and bounded errors -----------------------------------------------------

def test_alias_bomb_is_a_quick_short_422(client: TestClient) -> None:
    bomb = alias_bomb(8, 10)
    started = time.perf_counter()
    response = client.post("/v1/tasks", json={"target": "quick", "world_file": bomb})
    elapsed = time.perf_counter() - started
    assert response.status_code == 422
    assert elapsed < 1.0, elapsed
    assert len(response.content) < 1000, len(response.content)
    detail = response.json()["detail"]
    assert detail[0]["loc"] == ["body", "world_file"] and "aliases" in detail[0]["msg"]
    # fewer aliases than the limit, but still a billion-laugh expansion: refused by size
    small = alias_bomb(6, 10)
    assert small.count("*") <= MAX_YAML_ALIASES
    response = client.post("/v1/tasks", json={"target": "quick", "world_file": small})
    assert response.status_code == 422 and "50000 YAML nodes" in response.json()["detail"][0][
        "msg"]


def test_the_alias_bomb_is_refused_with_the_real_checker_too(make_settings: Make) -> None:
    from api.config import DEFAULT_TASK_CHECKER

    with TestClient(create_app(make_settings(task_checker=DEFAULT_TASK_CHECKER))) as client:
        started = time.perf_counter()
        response = client.post("/v1/tasks", json={"target": "cup", "world_file": alias_bomb()})
        assert response.status_code == 422 and time.perf_counter() - started < 1.0
        assert len(response.content) < 1000


def test_a_few_aliases_are_fine(client: TestClient) -> None:
    world = ("name: tiny\nsize: [4, 4]\nrooms:\n  - {name: a, category: kitchen, rect: &r "
             "[0, 0, 2, 4]}\n  - {name: b, category: kitchen, rect: *r}\n")
    assert client.post("/v1/tasks", json={"target": "quick", "world_file": world}
                       ).status_code == 202


def test_deep_yaml_and_deep_json_are_refused(client: TestClient) -> None:
    for depth, says in ((30, "deeper than 20"), (5000, "nesting depth")):
        deep = "a: " + "[" * depth + "]" * depth + "\n"
        response = client.post("/v1/tasks", json={"target": "quick", "world_file": deep})
        assert response.status_code == 422 and says in response.json()["detail"][0]["msg"]
    nested: Any = "cup"
    for _ in range(200):
        nested = {"descriptions": nested}
    response = client.post("/v1/tasks", json={**BODY, "qsr": nested})
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == [
        "body", "qsr"]


def test_every_validation_message_is_short(client: TestClient) -> None:
    huge = "x" * 200_000
    bodies: list[Any] = [
        {**BODY, huge: 1},  # an unknown field named by a huge key
        {**BODY, "strategy_options": {huge[:60]: huge[:190] + "/"}},
        {"target": "quick", "world_file": "a: [" + huge},  # YAML error at the end
        {"target": "quick", "world_file": f"{huge}: 1\n" + "b: *nope\n"},
        {**BODY, "world": "z" * 64},
    ]
    for body in bodies:
        response = client.post("/v1/tasks", json=body)
        assert response.status_code == 422
        assert len(response.content) < 2000, (len(response.content), response.text[:200])
        for item in response.json()["detail"]:
            assert len(item["msg"]) <= 300 and all(len(str(x)) <= 64 for x in item["loc"])


def test_deep_pddl_is_refused_before_the_planner(client: TestClient) -> None:
    deep = "(define (domain d) " + "(and " * 1000 + ")" * 1001
    for body, field in (({"domain": deep, "problem": "(define)"}, "domain"),
                        ({"domain": "(define)", "problem": deep}, "problem")):
        response = client.post("/v1/plans", json=body)
        assert response.status_code == 422
        assert response.json()["detail"][0]["loc"] == ["body", field]
    response = client.post("/v1/domains/check", json={"domain": "(define)", "problems": [deep]})
    assert response.status_code == 422 and "problems[0]" in response.json()["detail"][0]["msg"]


def test_pddl_names_are_bounded_and_errors_quote_a_short_excerpt(make_settings: Make) -> None:
    """A 100,000-character name (the planner's message quoted it whole: 100 KB) is refused
    before the planner; a 250-character one reaches it, and its messages are cut to 300."""
    def domain(name: str) -> str:
        return ("(define (domain d) (:predicates (p)) (:action a :parameters () "
                f":effect (and ({name}) (p))))")

    problem = "(define (problem p) (:domain d))"
    with TestClient(create_app(make_settings(plan_time_limit_s=60))) as client:
        started = time.perf_counter()
        huge = client.post("/v1/plans", json={"domain": domain("zz" + "q" * 100_000),
                                              "problem": problem})
        assert huge.status_code == 422 and time.perf_counter() - started < 1.0
        assert len(huge.content) < 400 and "more than 256 characters" in huge.text
        name = "zz" + "q" * 250
        response = client.post("/v1/plans", json={"domain": domain(name), "problem": problem})
        assert response.status_code == 422, response.text[:300]
        assert all(len(d["msg"]) <= 300 for d in response.json()["detail"])
        check = client.post("/v1/domains/check", json={"domain": domain(name)})
        assert check.status_code == 200 and len(check.content) < 3000
        assert all(len(d["message"]) <= 300 for d in check.json()["diagnostics"])


def test_no_error_echoes_the_request(client: TestClient) -> None:
    """Errors carry type, loc and msg only: never pydantic's `input` (the whole value)."""
    response = client.post("/v1/tasks", json={**BODY, "seed": "x" * 100_000})
    assert response.status_code == 422
    assert set(json.loads(response.content)["detail"][0]) == {"type", "loc", "msg"}
