"""Standard PDDL that Fast Downward reads: negative literals in :init (IPC movie) and names
shared by an object and a type (IPC tidybot) are read with a warning at their position; what
the planner still refuses is an error at its position, naming the construct and the action or
goal, in `check` as in the reader."""

from __future__ import annotations

import pytest

from avs_planner.errors import PddlError
from avs_planner.pddl import PddlSource, check, read_text

ROBBY = """(define (domain robby)
  (:requirements :strips :typing)
  (:types room)
  (:predicates (at-robby ?r - room) (visited ?r - room))
  (:action move :parameters (?from ?to - room)
    :precondition (at-robby ?from)
    :effect (and (not (at-robby ?from)) (at-robby ?to) (visited ?to))))
"""


def _robby_problem(init: str) -> str:
    return f"""(define (problem two-rooms) (:domain robby)
  (:objects rooma roomb - room)
  (:init {init})
  (:goal (visited roomb)))
"""


def _found(domain: str, problem: str | None) -> list[tuple[str, int, int, str, str]]:
    problems = [PddlSource("p.pddl", problem)] if problem is not None else []
    return [(d.file, d.line, d.column, d.severity.value, d.code)
            for d in check(PddlSource("d.pddl", domain), problems)]


def test_a_negative_init_literal_is_dropped_with_a_warning_where_it_is() -> None:
    problem = _robby_problem("(at-robby rooma) (not (at-robby roomb))")
    assert _found(ROBBY, problem) == [("p.pddl", 3, 27, "warning", "negative-init")]
    task = read_text(ROBBY, problem, "d.pddl", "p.pddl")
    assert [str(w) for w in task.warnings] == [
        "p.pddl:3:27: warning: a negative literal in :init is ignored: under the closed world "
        "a fact is false unless listed"]
    up = task.problem
    at_robby = up.fluent("at-robby")
    values = up.initial_values
    assert values[at_robby(up.object("rooma"))].bool_constant_value() is True
    assert values[at_robby(up.object("roomb"))].bool_constant_value() is False


@pytest.mark.parametrize(("init", "negative", "positive"), [
    ("(at-robby rooma) (not (at-robby rooma))", (3, 27), (3, 10)),
    ("(not (at-robby rooma)) (at-robby rooma)", (3, 10), (3, 33)),
])
def test_a_negative_init_literal_contradicting_a_true_one_is_an_error_naming_both(
        init: str, negative: tuple[int, int], positive: tuple[int, int]) -> None:
    problem = _robby_problem(init)
    errors = [d for d in check(PddlSource("d.pddl", ROBBY), [PddlSource("p.pddl", problem)])
              if d.is_error]
    assert [(d.line, d.column, d.code) for d in errors] == [(*negative, "contradictory-init")]
    assert f"p.pddl:{negative[0]}:{negative[1]}" in errors[0].message
    assert f"(at-robby rooma) at p.pddl:{positive[0]}:{positive[1]}" in errors[0].message
    with pytest.raises(PddlError) as exc:
        read_text(ROBBY, problem, "d.pddl", "p.pddl")
    assert (exc.value.line, exc.value.column) == negative
    assert "contradicts" in exc.value.message


def test_a_negative_literal_of_another_atom_is_no_contradiction() -> None:
    problem = _robby_problem("(at-robby rooma) (not (at-robby roomb)) (not (visited rooma))")
    assert [code for *_, severity, code in _found(ROBBY, problem)] == ["negative-init"] * 2


CART = """(define (domain cart)
  (:requirements :strips :typing)
  (:types robot cart room)
  (:constants robot - robot)
  (:predicates (at ?c - cart ?r - room) (holds ?r - robot ?c - cart))
  (:action push :parameters (?c - cart ?a ?b - room)
    :precondition (and (holds robot ?c) (at ?c ?a))
    :effect (and (not (at ?c ?a)) (at ?c ?b))))
"""

CART_PROBLEM = """(define (problem tidy) (:domain cart)
  (:objects cart - cart room hall - room)
  (:init (holds robot cart) (at cart room))
  (:goal (at cart hall)))
"""


def test_objects_and_constants_named_as_types_are_read_with_a_warning_where_they_are() -> None:
    assert _found(CART, CART_PROBLEM) == [
        ("d.pddl", 4, 15, "warning", "name-clash"),
        ("p.pddl", 2, 13, "warning", "name-clash"),
        ("p.pddl", 2, 25, "warning", "name-clash"),
    ]
    task = read_text(CART, CART_PROBLEM, "d.pddl", "p.pddl")
    assert {o.name for o in task.problem.all_objects} == {"robot", "cart", "room", "hall"}
    messages = [w.message for w in task.warnings]
    assert messages[1].startswith("object 'cart' has the same name as a type (")
    assert messages[2].startswith("object 'room' has the same name as a type (")
    assert messages[0].startswith("constant 'robot' has the same name as a type (")


def test_a_numeric_goal_condition_is_refused_where_it_is_naming_the_goal() -> None:
    domain = ROBBY.replace("(:requirements :strips :typing)",
                           "(:requirements :strips :typing :numeric-fluents)").replace(
        "(visited ?r - room))", "(visited ?r - room))\n  (:functions (battery))")
    problem = _robby_problem("(at-robby rooma) (= (battery) 3)").replace(
        "(:goal (visited roomb))", "(:goal (and (visited roomb) (> (battery) 1)))")
    errors = [e for e in _found(domain, problem) if e[3] == "error"]
    assert errors == [("p.pddl", 4, 31, "error", "unsupported-goal")]
    with pytest.raises(PddlError, match=r"the numeric condition \(> \(battery\) 1\) in the "
                       r"goal is not supported") as exc:
        read_text(domain, problem, "d.pddl", "p.pddl")
    assert (exc.value.file, exc.value.line, exc.value.column) == ("p.pddl", 4, 31)


LAMPS = """(define (domain lamps)
  (:requirements :strips :typing :conditional-effects :disjunctive-preconditions
                 :numeric-fluents)
  (:types lamp)
  (:predicates (on ?l - lamp) (lit ?l - lamp) (broken ?l - lamp))
  (:functions (power))
  (:action switch :parameters (?l - lamp)
    :precondition (> (power) 0)
    :effect (and (on ?l) (when (or (lit ?l) (broken ?l)) (not (lit ?l)))
                 (when (on ?l) (decrease (power) 1)))))
"""


def test_what_only_the_planner_refuses_in_an_action_is_an_error_without_a_problem() -> None:
    found = check(PddlSource("d.pddl", LAMPS))
    errors = [(d.line, d.column, d.code) for d in found if d.is_error]
    assert errors == [(8, 19, "unsupported-condition"), (9, 32, "unsupported-effect"),
                      (10, 32, "unsupported-effect")]
    messages = [d.message for d in found if d.is_error]
    assert all("action 'switch'" in m for m in messages)
    assert "(or (lit ?l) (broken ?l))" in messages[1]
    assert "(decrease (power) 1)" in messages[2]
