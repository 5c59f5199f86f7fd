"""Individual linter rules on tiny inputs: warnings, probabilities, did-you-mean, conversions."""

from __future__ import annotations

from pathlib import Path

import pyparsing
import pytest

from avs_planner.errors import PddlError
from avs_planner.pddl import PddlSource, Severity, check, read_text
from avs_planner.pddl.reader import _convert
from avs_planner.pddl.sexpr import is_number, parse_sexprs

DATA = Path(__file__).parent / "data"
DOMAIN = (DATA / "base-domain.pddl").read_text()
PROBLEM = (DATA / "base-problem.pddl").read_text()


def _codes(domain: str = DOMAIN, problem: str | None = PROBLEM) -> list[tuple[str, str]]:
    problems = [PddlSource("p", problem)] if problem is not None else []
    return [(d.code, d.severity.value) for d in check(PddlSource("d", domain), problems)]


def test_declared_but_unused_requirement_is_a_warning() -> None:
    domain = DOMAIN.replace(":action-costs", ":action-costs :conditional-effects")
    assert _codes(domain) == [("unused-requirement", "warning")]


def test_adl_covers_negative_preconditions() -> None:
    domain = DOMAIN.replace(":negative-preconditions", ":adl")
    assert ("missing-requirement", "warning") not in _codes(domain)


def test_two_probabilistic_effects_multiply() -> None:
    domain = DOMAIN.replace(
        "(increase (total-cost) 1))))",
        "(probabilistic 1/2 (clear ?x)) (increase (total-cost) 1))))",
    )
    task = read_text(domain, PROBLEM)
    assert task.constant_success("place") == pytest.approx(0.45)


def test_probabilistic_inside_when_is_rejected_with_position() -> None:
    domain = DOMAIN.replace(
        "(increase (total-cost) 1))))",
        "(when (clear ?x) (probabilistic 0.5 (clear ?x))) (increase (total-cost) 1))))",
    )
    with pytest.raises(PddlError) as exc:
        read_text(domain, PROBLEM)
    line = domain.splitlines()[exc.value.line - 1]
    assert line[exc.value.column - 1 :].startswith("(probabilistic 0.5")


def test_probability_fluent_with_a_constant_argument() -> None:
    domain = DOMAIN.replace("(p-grip ?x) (and (holding", "(p-grip ?x) (and (holding")
    domain = domain.replace("(probabilistic 9/10", "(probabilistic (p-drop floor)")
    domain = domain.replace(
        "(p-grip ?x - block) - number",
        "(p-grip ?x - block) - number\n              (p-drop ?t - table) - number",
    )
    problem = PROBLEM.replace(
        "(= (total-cost) 0)", "(= (total-cost) 0) (= (p-drop floor) 1) (= (p-drop desk) 0.5)"
    )
    task = read_text(domain, problem)
    assert str(task.success["place"]) == "p-drop(floor)"


def test_every_probability_instance_needs_a_value() -> None:
    problem = PROBLEM.replace("(= (p-grip b) 0.7)", "")
    found = check(PddlSource("d", DOMAIN), [PddlSource("p", problem)])
    assert [d.code for d in found] == ["probability-not-in-init"]
    assert "(p-grip b)" in found[0].message and found[0].severity is Severity.ERROR


def test_did_you_mean_for_types_and_objects() -> None:
    domain = DOMAIN.replace("(holding ?x - block))", "(holding ?x - blocks))")
    found = check(PddlSource("d", domain))
    assert any("unknown type 'blocks' (did you mean 'block'?)" in d.message for d in found)
    problem = PROBLEM.replace("(on a desk)", "(on a dexk)")
    found = check(PddlSource("d", DOMAIN), [PddlSource("p", problem)])
    assert any("(did you mean 'desk'?)" in d.message for d in found)


def test_goal_with_quantifier_is_not_judged_true() -> None:
    problem = PROBLEM.replace("(and (on a desk))", "(forall (?b - block) (on ?b desk))")
    domain = DOMAIN.replace(":probabilistic-effects", ":probabilistic-effects :adl")
    codes = _codes(domain, problem)
    assert ("goal-true-in-init", "warning") not in codes and not any(s == "error" for _, s in codes)


def test_unbalanced_parenthesis_points_at_the_opening_one() -> None:
    with pytest.raises(PddlError) as exc:
        parse_sexprs("(a\n  (b c)\n  (d e)", "f.pddl")
    assert (exc.value.file, exc.value.line, exc.value.column) == ("f.pddl", 1, 1)


def test_numbers_and_fractions() -> None:
    assert is_number("3/10") and is_number("-0.5") and is_number("7")
    assert not is_number("3/") and not is_number("a/b") and not is_number("1/2/3")


def test_pyparsing_errors_keep_their_position() -> None:
    exc = pyparsing.ParseException("(define\n  (domain x", 12, "Expected ')'")
    error = _convert(exc, "d.pddl")
    assert (error.file, error.line, error.column) == ("d.pddl", 2, 5)


def test_up_messages_with_positions_are_used() -> None:
    error = _convert(SyntaxError("bad thing\nError from line: 4, col 7 to line: 4, col 9"), "d")
    assert (error.line, error.column) == (4, 7) and "bad thing" in error.message


def test_probability_fluent_over_a_type_with_no_objects_needs_no_value() -> None:
    """An episode's problem with no placeholder left has no (p-placeholder-category ...)
    instance at all: nothing to give a value to, so no error (the file is still read)."""
    domain = DOMAIN.replace("(:types block table - object)", "(:types block table bin - object)")
    domain = domain.replace(
        "(lift-cost ?x - block) - number)",
        "(lift-cost ?x - block) - number\n              (p-toss ?b - bin) - number)",
    )
    domain = domain.replace("(:action place", """(:action toss
    :parameters (?x - block ?b - bin)
    :precondition (holding ?x)
    :effect (and (probabilistic (p-toss ?b) (not (holding ?x))) (increase (total-cost) 1)))
  (:action place""")
    assert _codes(domain) == []
    read_text(domain, PROBLEM)
    with_bin = PROBLEM.replace("desk - table)", "desk - table bin1 - bin)")
    assert ("probability-not-in-init", "error") in _codes(domain, with_bin)
