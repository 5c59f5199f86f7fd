"""Broken inputs: each mistake is found at the right line and column, with the right code;
and the other way (`accepted.json`): what `avs plan` plans for, `avs domain check` passes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avs_planner.errors import PddlError
from avs_planner.pddl import PddlSource, check, read_text
from avs_planner.pddl.check import NOT_GROUNDED

DATA = Path(__file__).parent / "data"
DOMAIN = (DATA / "base-domain.pddl").read_text()
PROBLEM = (DATA / "base-problem.pddl").read_text()
CASES = json.loads((DATA / "broken.json").read_text())
# Valid inputs near the edge of what the planner takes (goals that are no conjunction of
# literals): no error from the checks, read, and planned for
ACCEPTED = json.loads((DATA / "accepted.json").read_text())
ERRORS = [c for c in CASES if c.get("severity", "error") == "error"]
# What the reader accepts, as Fast Downward does, or repairs: a warning, never an error
LENIENT = [c for c in CASES if c.get("severity") == "warning"]
# Errors the reader stops at, and those only the planner stops at (the reader still reads)
READER_ERRORS = [c for c in ERRORS if c["code"] not in NOT_GROUNDED]
PLANNER_ERRORS = [c for c in ERRORS if c["code"] in NOT_GROUNDED]


def mutate(case: dict) -> tuple[str, str, tuple[str, int, int]]:
    """The broken (domain, problem) texts and the expected (file, line, column); a case's
    `also` is one more replacement made first (e.g. the predicate a derived rule defines)."""
    texts = {"domain": DOMAIN, "problem": PROBLEM}
    also = case.get("also")
    if also is not None:
        assert texts[also["file"]].count(also["old"]) == 1, case["name"]
        texts[also["file"]] = texts[also["file"]].replace(also["old"], also["new"])
    original = texts[case["file"]]
    assert original.count(case["old"]) == 1, case["name"]
    broken = original.replace(case["old"], case["new"])
    texts[case["file"]] = broken
    find = broken.rfind if case.get("last") else broken.find
    index = find(case["anchor"]) + case.get("offset", 0)
    assert index >= 0, case["name"]
    line = broken.count("\n", 0, index) + 1
    column = index - (broken.rfind("\n", 0, index) + 1) + 1
    return texts["domain"], texts["problem"], (f"{case['file']}.pddl", line, column)


def test_the_base_files_are_clean() -> None:
    found = check(PddlSource("domain.pddl", DOMAIN), [PddlSource("problem.pddl", PROBLEM)])
    assert found == []
    assert read_text(DOMAIN, PROBLEM).constant_success("place") == pytest.approx(0.9)


def test_at_least_fifteen_distinct_mistakes() -> None:
    assert len({c["name"] for c in ERRORS}) >= 15
    assert len({c["code"] for c in ERRORS}) >= 15


@pytest.mark.parametrize("case", CASES, ids=lambda c: c["name"])
def test_check_reports_the_mistake_where_it_is(case: dict) -> None:
    domain, problem, where = mutate(case)
    found = check(PddlSource("domain.pddl", domain), [PddlSource("problem.pddl", problem)])
    severity = case.get("severity", "error")
    errors = [(d.file, d.line, d.column, d.code) for d in found if d.severity == severity]
    assert (*where, case["code"]) in errors


@pytest.mark.parametrize("case", LENIENT, ids=lambda c: c["name"])
def test_reader_reads_on_and_passes_the_warning(case: dict) -> None:
    domain, problem, where = mutate(case)
    task = read_text(domain, problem, "domain.pddl", "problem.pddl")
    assert (*where, case["code"]) in [(w.file, w.line, w.column, w.code) for w in task.warnings]
    assert all(str(w).startswith(f"{w.file}:{w.line}:{w.column}: warning: ")
               for w in task.warnings)


@pytest.mark.parametrize("case", READER_ERRORS, ids=lambda c: c["name"])
def test_reader_raises_the_first_error(case: dict) -> None:
    domain, problem, _ = mutate(case)
    found = check(PddlSource("domain.pddl", domain), [PddlSource("problem.pddl", problem)])
    first = next(d for d in found if d.is_error)
    with pytest.raises(PddlError) as exc:
        read_text(domain, problem, "domain.pddl", "problem.pddl")
    assert (exc.value.file, exc.value.line, exc.value.column) == (
        first.file,
        first.line,
        first.column,
    )
    assert str(exc.value).startswith(f"{first.file}:{first.line}:{first.column}: ")


@pytest.mark.parametrize("case", PLANNER_ERRORS, ids=lambda c: c["name"])
def test_reader_reads_what_only_the_planner_refuses_and_keeps_where_it_is(case: dict) -> None:
    domain, problem, where = mutate(case)
    task = read_text(domain, problem, "domain.pddl", "problem.pddl")
    assert task.model.actions  # the model read (a domain with derived predicates has no UP one)
    assert [(d.file, d.line, d.column, d.code) for d in task.not_grounded] == [
        (*where, case["code"])]


@pytest.mark.parametrize("case", ACCEPTED, ids=lambda c: c["name"])
def test_check_and_plan_accept_it_alike(case: dict) -> None:
    from unified_planning.engines.plan_validator import SequentialPlanValidator

    from avs_planner.cp.planner import plan
    from avs_planner.cp.search import PlanStatus, SearchOptions
    from avs_planner.up_engine import to_up_plan

    texts = {"domain": DOMAIN, "problem": PROBLEM}
    assert texts[case["file"]].count(case["old"]) == 1, case["name"]
    texts[case["file"]] = texts[case["file"]].replace(case["old"], case["new"])
    found = check(PddlSource("domain.pddl", texts["domain"]),
                  [PddlSource("problem.pddl", texts["problem"])])
    assert [d for d in found if d.is_error] == []
    assert [d.code for d in found if d.code == "goal-true-in-init"] == (
        [case["warning"]] if "warning" in case else [])
    task = read_text(texts["domain"], texts["problem"], "domain.pddl", "problem.pddl")
    result = plan(task, SearchOptions())
    assert result.status is PlanStatus.SOLVED and len(result.plan) == case["steps"]
    valid = SequentialPlanValidator().validate(task.problem,
                                               to_up_plan(task.problem, result.plan))
    assert valid.status.name == "VALID"
