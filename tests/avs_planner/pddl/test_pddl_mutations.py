"""Property: whatever a mutation does to valid PDDL, only the project's PddlError escapes."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from avs_planner.errors import PddlError
from avs_planner.pddl import PddlSource, check, read_text

DATA = Path(__file__).parent / "data"
ROOT = Path(__file__).resolve().parents[3]
BASE = ((DATA / "base-domain.pddl").read_text(), (DATA / "base-problem.pddl").read_text())
AVS = (
    (ROOT / "domains/avs/domain.pddl").read_text(),
    (ROOT / "domains/avs/problems/table-known.pddl").read_text(),
)
TOKENS = [
    "(", ")", "?x", "?zz", "-", "block", "either", "(either a b)", "not", "and", "forall",
    "(probabilistic", "probabilistic", "1.5", "3/0", "-1", ":typing", ":effect", "(= ", "\n",
    ";", "(and)", "()", "(increase (total-cost) 1)", "object", "number", "\t", "é", ":init",
]


@st.composite
def mutated(draw: st.DrawFn, texts: tuple[str, str]) -> tuple[str, str]:
    """Apply 1-3 edits (delete, insert a token, duplicate, swap) to the domain or problem."""
    domain, problem = texts
    for _ in range(draw(st.integers(1, 3))):
        which = draw(st.booleans())
        text = domain if which else problem
        text = _edit(draw, text)
        domain, problem = (text, problem) if which else (domain, text)
    return domain, problem


def _edit(draw: st.DrawFn, text: str) -> str:
    i = draw(st.integers(0, len(text)))
    j = min(len(text), i + draw(st.integers(0, 40)))
    kind = draw(st.sampled_from(["delete", "insert", "duplicate", "swap"]))
    if kind == "delete":
        return text[:i] + text[j:]
    if kind == "insert":
        return text[:i] + " " + draw(st.sampled_from(TOKENS)) + " " + text[i:]
    if kind == "duplicate":
        return text[:j] + text[i:j] + text[j:]
    k = min(len(text), j + (j - i))
    return text[:i] + text[j:k] + text[i:j] + text[k:]


def _only_pddl_errors(domain: str, problem: str) -> None:
    found = check(PddlSource("d.pddl", domain), [PddlSource("p.pddl", problem)])
    for diagnostic in found:
        assert diagnostic.file in ("d.pddl", "p.pddl")
        assert diagnostic.line >= 1 and diagnostic.column >= 1
    try:
        task = read_text(domain, problem, "d.pddl", "p.pddl")
    except PddlError as exc:
        assert exc.file in ("d.pddl", "p.pddl") and exc.line >= 1 and exc.column >= 1
        return
    assert not any(d.is_error for d in found)
    assert task.problem is not None


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(BASE))
def test_mutated_small_domain_raises_only_pddl_error(texts: tuple[str, str]) -> None:
    _only_pddl_errors(*texts)


@pytest.mark.slow
@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated(AVS))
def test_mutated_avs_domain_raises_only_pddl_error(texts: tuple[str, str]) -> None:
    _only_pddl_errors(*texts)
