"""/v1/plans and /v1/domains/check against the real PDDL reader, linter and planner."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app

DOMAIN = """(define (domain lamp)
  (:requirements :strips :typing :action-costs :probabilistic-effects)
  (:types room)
  (:predicates (at ?r - room) (lit ?r - room) (door ?a ?b - room))
  (:functions (total-cost) - number)
  (:action go
    :parameters (?a ?b - room)
    :precondition (and (at ?a) (door ?a ?b))
    :effect (and (not (at ?a)) (at ?b) (increase (total-cost) 1)))
  (:action switch-on
    :parameters (?r - room)
    :precondition (at ?r)
    :effect (and (probabilistic 0.5 (lit ?r)) (increase (total-cost) 2))))
"""
PROBLEM = """(define (problem two-rooms)
  (:domain lamp)
  (:objects hall kitchen cellar - room)
  (:init (at hall) (door hall kitchen) (door kitchen hall) (= (total-cost) 0))
  (:goal (lit kitchen))
  (:metric minimize (total-cost)))
"""


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[TestClient]:
    data = tmp_path_factory.mktemp("plans")
    settings = Settings(data_dir=data, workers=1, plan_workers=1, worlds_dir=Path(data),
                        api_key=None, warm_workers=False)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def test_plan_solved(client: TestClient) -> None:
    response = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM, "reward": 10})
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["status"] == "solved"
    assert body["plan"] == ["(go hall kitchen)", "(switch-on kitchen)"]
    assert body["cost"] == 3 and body["probability"] == 0.5 and body["objective"] == 8


def test_a_disjunctive_goal_is_planned_for(client: TestClient) -> None:
    problem = PROBLEM.replace("(:goal (lit kitchen))",
                              "(:goal (exists (?r - room) (and (lit ?r) (not (at ?r)))))")
    response = client.post("/v1/plans", json={"domain": DOMAIN, "problem": problem,
                                              "reward": 10})
    assert response.status_code == 200, response.text
    body = response.json()  # light the hall, then leave it: 2 + 1, with p = 0.5
    assert body["status"] == "solved" and body["plan"] == ["(switch-on hall)",
                                                          "(go hall kitchen)"]
    assert body["cost"] == 3 and body["probability"] == 0.5


def test_undeclared_requirement_is_a_warning_not_a_422(client: TestClient) -> None:
    domain = DOMAIN.replace(":strips :typing", ":strips")
    response = client.post("/v1/plans", json={"domain": domain, "problem": PROBLEM})
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["status"] == "solved" and body["plan"] == ["(go hall kitchen)",
                                                            "(switch-on kitchen)"]
    (warning,) = body["warnings"]
    assert warning["severity"] == "warning" and warning["code"] == "missing-requirement"
    assert (warning["line"], warning["column"]) == (3, 3) and ":typing" in warning["message"]
    assert client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM}
                       ).json()["warnings"] == []


def test_plan_unsolvable_is_a_200_answer(client: TestClient) -> None:
    problem = PROBLEM.replace("(:goal (lit kitchen))", "(:goal (lit cellar))")
    body = client.post("/v1/plans", json={"domain": DOMAIN, "problem": problem}).json()
    assert body["status"] == "unsolvable" and body["plan"] == []


def test_malformed_pddl_is_422_with_line_and_column(client: TestClient) -> None:
    problem = PROBLEM.replace("(:goal (lit kitchen))", "(:goal (lt kitchen))")
    response = client.post("/v1/plans", json={"domain": DOMAIN, "problem": problem})
    assert response.status_code == 422
    error = response.json()["detail"][0]
    assert error["loc"] == ["body", "problem"] and error["line"] == 5 and error["column"] == 11
    assert "lt" in error["msg"]
    broken = client.post("/v1/plans", json={"domain": DOMAIN[:-3], "problem": PROBLEM})
    assert broken.status_code == 422 and broken.json()["detail"][0]["loc"] == ["body", "domain"]


def test_bad_options_are_422(client: TestClient) -> None:
    response = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM, "weight": 0})
    assert response.status_code == 422 and response.json()["detail"][0]["loc"][-1] == "weight"
    extra = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM, "speed": 1})
    assert extra.status_code == 422


def test_plan_patience_and_stopped_by(client: TestClient) -> None:
    from bench.avs_generator import AvsSize, generate

    domain = (Path(__file__).resolve().parents[2] / "domains/avs/domain.pddl").read_text()
    problem = generate(AvsSize(8, 2, 2, 4), 5)  # a first plan after 18 expansions
    body = client.post("/v1/plans", json={"domain": domain, "problem": problem,
                                          "patience": 50}).json()
    assert body["status"] == "solved" and body["stopped_by"] == "patience"
    assert body["expanded"] == 18 + 50 + 1
    plain = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM}).json()
    assert plain["stopped_by"] is None
    bad = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM, "patience": -1})
    assert bad.status_code == 422 and bad.json()["detail"][0]["loc"][-1] == "patience"


def test_domain_check_reports_diagnostics(client: TestClient) -> None:
    typo = PROBLEM.replace("(:goal (lit kitchen))", "(:goal (lt kitchen))")
    body = {"domain": DOMAIN, "problems": [PROBLEM, typo]}
    response = client.post("/v1/domains/check", json=body)
    assert response.status_code == 200
    body = response.json()
    assert body["ok"] is False and body["errors"] == 1
    finding = body["diagnostics"][0]
    assert finding["file"] == "problem[1]" and (finding["line"], finding["column"]) == (5, 11)
    assert finding["code"] == "unknown-predicate" and "did you mean 'lit'" in finding["message"]
    clean = client.post("/v1/domains/check", json={"domain": DOMAIN, "problems": [PROBLEM]})
    assert clean.json()["ok"] is True


def test_domain_check_of_garbage(client: TestClient) -> None:
    body = client.post("/v1/domains/check", json={"domain": "(define (domain"}).json()
    assert body["ok"] is False and body["diagnostics"][0]["file"] == "domain"


def test_plan_job_over_its_wall_clock_is_504(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, worlds_dir=tmp_path, plan_time_limit_s=0.05,
                        api_key=None, preload_planner=False)
    with TestClient(create_app(settings)) as client:
        response = client.post("/v1/plans", json={"domain": DOMAIN, "problem": PROBLEM})
        assert response.status_code == 504 and "wall-clock limit" in response.json()["detail"]
        assert client.get("/v1/health").status_code == 200  # the killed worker is replaced
