"""The planner on what the reader now takes (negative :init literals, objects named as types),
and what it still refuses: named with the construct, the action or goal, and FILE:LINE:COL,
by `avs plan` and `avs domain check` alike."""

from __future__ import annotations

from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.cp.conditional import MAX_CONDITIONS
from avs_planner.cp.grounding import GroundingCache, ground, grounding_diagnostics
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.cp.unsupported import UnsupportedError
from avs_planner.pddl import read_text
from tests.avs_planner.cp.pddl_cases import lamps

MOVIE = """(define (domain movie-robby)
  (:requirements :strips :typing)
  (:types room snack)
  (:predicates (at-robby ?r - room) (have ?s - snack) (in ?s - snack ?r - room))
  (:action move :parameters (?from ?to - room)
    :precondition (at-robby ?from)
    :effect (and (not (at-robby ?from)) (at-robby ?to)))
  (:action get :parameters (?s - snack ?r - room)
    :precondition (and (at-robby ?r) (in ?s ?r))
    :effect (have ?s)))
"""

MOVIE_PROBLEM = """(define (problem snacks) (:domain movie-robby)
  (:objects rooma roomb - room chips - snack)
  (:init (at-robby rooma) (not (at-robby roomb)) (in chips roomb) (not (have chips)))
  (:goal (have chips)))
"""

TIDY = """(define (domain tidy)
  (:requirements :strips :typing)
  (:types robot cart place)
  (:predicates (at ?c - cart ?p - place) (grasped ?r - robot ?c - cart))
  (:action push :parameters (?r - robot ?c - cart ?a ?b - place)
    :precondition (and (grasped ?r ?c) (at ?c ?a))
    :effect (and (not (at ?c ?a)) (at ?c ?b))))
"""

TIDY_PROBLEM = """(define (problem tidy1) (:domain tidy)
  (:objects robot - robot cart - cart place table - place)
  (:init (grasped robot cart) (at cart place))
  (:goal (at cart table)))
"""


@pytest.mark.parametrize(("domain", "problem", "expected", "warnings"), [
    (MOVIE, MOVIE_PROBLEM, ["(move rooma roomb)", "(get chips roomb)"], ["negative-init"] * 2),
    (TIDY, TIDY_PROBLEM, ["(push robot cart place table)"], ["name-clash"] * 3),
], ids=["negative-init", "objects-named-as-types"])
def test_what_the_reader_now_takes_is_planned(domain, problem, expected, warnings) -> None:
    task = read_text(domain, problem, "d.pddl", "p.pddl")
    assert [w.code for w in task.warnings] == warnings
    result = plan(task, SearchOptions())
    assert result.status is PlanStatus.SOLVED
    assert [step.label for step in result.plan] == expected


def test_the_effect_condition_limit_names_the_action_where_it_is_declared() -> None:
    task = read_text(*lamps(MAX_CONDITIONS + 1), "d.pddl", "p.pddl")
    with pytest.raises(UnsupportedError) as exc:
        ground(task, cache=GroundingCache())
    assert str(exc.value).startswith(
        f"d.pddl:6:12: action flip, as (flip ): {MAX_CONDITIONS + 1} state-dependent effect "
        f"conditions; at most {MAX_CONDITIONS} are supported")
    assert (exc.value.position.line, exc.value.position.column) == (6, 12)
    [found] = grounding_diagnostics(task)
    assert (found.file, found.line, found.column, found.code) == ("d.pddl", 6, 12,
                                                                  "unsupported")
    assert found.is_error and found.message == exc.value.message
    assert grounding_diagnostics(read_text(*lamps(MAX_CONDITIONS), "d.pddl", "p.pddl")) == []


def test_a_goal_conjunct_the_grounder_refuses_is_placed_at_that_conjunct() -> None:
    """Past the reader's check (the goal is replaced in unified-planning), the grounder still
    places the conjunct it refuses (a numeric comparison, here inside a disjunction, which
    itself is planned for), from the positions the reader recorded."""
    problem_text = MOVIE_PROBLEM.replace("(:goal (have chips))",
                                         "(:goal (and (at-robby rooma) (have chips)))")
    task = read_text(MOVIE, problem_text, "d.pddl", "p.pddl")
    up = task.problem.clone()
    em = up.environment.expression_manager
    at_robby, have = up.fluent("at-robby"), up.fluent("have")
    up.clear_goals()
    up.add_goal(em.And(at_robby(up.object("rooma")),
                       em.Or(have(up.object("chips")), em.LT(em.Int(1), em.Int(2)))))
    moved = type(task)(up, sources=task.sources)
    with pytest.raises(UnsupportedError, match=r"^p\.pddl:4:32: unsupported goal condition "
                       r"\(have\(chips\) or \(1 < 2\)\): unsupported condition \(1 < 2\) "
                       r"\(a numeric comparison;"):
        ground(moved, cache=GroundingCache())
    up.clear_goals()  # three conjuncts against the text's two: the goal's own position
    up.add_goal(em.And(at_robby(up.object("rooma")), have(up.object("chips")),
                       em.Or(have(up.object("chips")), em.LT(em.Int(1), em.Int(2)))))
    with pytest.raises(UnsupportedError, match=r"^p\.pddl:4:10: unsupported goal condition"):
        ground(type(task)(up, sources=task.sources), cache=GroundingCache())


def test_a_task_built_without_the_reader_is_named_without_a_position() -> None:
    task = read_text(*lamps(MAX_CONDITIONS + 1))
    with pytest.raises(UnsupportedError) as exc:
        ground(type(task)(task.problem), cache=GroundingCache())
    assert exc.value.position is None
    assert str(exc.value).startswith("action flip, as (flip ): ")


def _write(tmp_path: Path, domain: str, problem: str) -> tuple[str, str]:
    (tmp_path / "d.pddl").write_text(domain)
    (tmp_path / "p.pddl").write_text(problem)
    return str(tmp_path / "d.pddl"), str(tmp_path / "p.pddl")


def test_plan_and_domain_check_refuse_the_effect_condition_limit_at_one_place(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    domain, problem = _write(tmp_path, *lamps(MAX_CONDITIONS + 1))
    where = f"{domain}:6:12: "
    assert main(["plan", domain, problem]) == 1
    assert f"avs: error: {where}action flip, as (flip ): " in capsys.readouterr().err
    assert main(["domain", "check", domain, problem]) == 1
    out = capsys.readouterr().out
    assert f"{where}error: action flip, as (flip ): {MAX_CONDITIONS + 1} state-dependent" in out


def test_plan_and_domain_check_refuse_a_when_condition_at_one_place(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    domain_text = lamps(2)[0].replace("(when (on ?l) (lit ?l))",
                                       "(when (or (on ?l) (lit ?l)) (lit ?l))")
    domain, problem = _write(tmp_path, domain_text, lamps(2)[1])
    task = read_text(domain_text, lamps(2)[1])  # the reader reads it (other engines may)
    assert [d.code for d in task.not_grounded] == ["unsupported-effect"]
    where = f"{domain}:7:51: "
    assert main(["plan", domain, problem]) == 1
    err = capsys.readouterr().err
    assert f"avs: error: {where}the condition (or (on ?l) (lit ?l)) of a conditional " \
           "effect of action 'flip' is not supported" in err
    assert main(["domain", "check", domain]) == 1  # found without a problem as well
    assert f"{where}error: the condition (or (on ?l) (lit ?l))" in capsys.readouterr().out


@pytest.mark.parametrize(("domain_text", "problem_text", "warned"), [
    (MOVIE, MOVIE_PROBLEM, ["3:27", "3:67"]),
    (TIDY, TIDY_PROBLEM, ["2:13", "2:27", "2:39"]),
], ids=["negative-init", "objects-named-as-types"])
def test_domain_check_passes_what_plan_now_takes(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], domain_text: str,
        problem_text: str, warned: list[str]) -> None:
    domain, problem = _write(tmp_path, domain_text, problem_text)
    assert main(["domain", "check", domain, problem]) == 0
    out = capsys.readouterr().out
    assert [line.split(": warning: ")[0] for line in out.splitlines()] == [
        f"{problem}:{at}" for at in warned]
    assert main(["plan", domain, problem]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("(")  # a plan, one step a line
    assert captured.err.count(": warning: ") == len(warned)
