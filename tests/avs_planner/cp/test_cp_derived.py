"""cp/derived.py: the per-structure rows filled in on demand equal a fresh sort, and the
compiled grounding fixpoints (`avs_planner.cp._fixpoint`) compute what the numpy versions
compute: relaxed reachability and backward relevance, on structures of AVS, IPC and a domain
with disjunctive preconditions, from random initial states, allowed rows and goals."""

from __future__ import annotations

import os
import random

import numpy as np
import pytest
from unified_planning.io import PDDLReader

from avs_planner.cp import derived
from avs_planner.cp.grounding import GroundingCache, world_state
from avs_planner.pddl import read_text
from avs_planner.pddl.model import ProbabilisticProblem

from .conftest import AVS_DOMAIN, IPC

DISJUNCTIVE = """
(define (domain doors)
  (:requirements :strips :typing :disjunctive-preconditions :negative-preconditions)
  (:types room key)
  (:predicates (at ?r - room) (door ?a - room ?b - room) (has ?k - key) (opens ?k - key ?r - room)
               (open ?r - room) (alarm))
  (:action pass
    :parameters (?a - room ?b - room)
    :precondition (and (at ?a) (door ?a ?b) (or (open ?b) (not (alarm))))
    :effect (and (not (at ?a)) (at ?b)))
  (:action unlock
    :parameters (?k - key ?r - room)
    :precondition (and (has ?k) (or (opens ?k ?r) (not (alarm))))
    :effect (and (open ?r) (alarm)))
  (:action take
    :parameters (?k - key)
    :precondition (and)
    :effect (has ?k)))
"""
DISJUNCTIVE_PROBLEM = """
(define (problem p) (:domain doors)
  (:objects r1 r2 r3 r4 - room k1 k2 - key)
  (:init (at r1) (door r1 r2) (door r2 r3) (door r3 r4) (door r2 r1) (opens k1 r3) (alarm))
  (:goal (and (at r4))))
"""

needs_fixpoint = pytest.mark.skipif(derived._fixpoint is None,
                                    reason="compiled fixpoints not built")


def test_the_compiled_fixpoints_are_built():
    """CI must not fall back silently: set AVS_ALLOW_NO_NATIVE=1 where no compiler exists."""
    if os.environ.get("AVS_ALLOW_NO_NATIVE") == "1":
        pytest.skip("AVS_ALLOW_NO_NATIVE=1")
    assert derived._fixpoint is not None, "avs_planner.cp._fixpoint did not import"


def _problems(corridor):
    yield corridor
    yield read_text(DISJUNCTIVE, DISJUNCTIVE_PROBLEM, "doors.pddl", "p.pddl")
    from bench.avs_generator import AvsSize, generate

    yield read_text(AVS_DOMAIN.read_text(), generate(AvsSize(8, 2, 2, 4), 1), "d.pddl", "p8")
    for domain in ("blocks", "logistics", "elevators"):
        folder = IPC / domain
        if folder.is_dir():
            yield ProbabilisticProblem(PDDLReader().parse_problem(
                str(folder / "domain.pddl"), str(folder / "instance-1.pddl")))


@needs_fixpoint
def test_compiled_fixpoints_match_numpy(corridor):
    rng = np.random.default_rng(7)
    pick = random.Random(7)
    clause_rows = 0
    for pproblem in _problems(corridor):
        st = GroundingCache().structure(pproblem, world_state(pproblem.problem))
        clause_rows += len(st.clauses)
        n = len(st.facts)
        for trial in range(12):
            init = np.zeros(n + 2, dtype=bool)
            init[:n] = rng.random(n) < (0.1 if trial % 2 else 0.4)
            init[n] = True
            allowed = rng.random(st.size) < (1.0 if trial < 3 else 0.7)
            reach = derived.reachable(st, init, allowed)
            assert np.array_equal(reach, derived.reachable_numpy(st, init, allowed))
            goal = sum(1 << f for f in pick.sample(range(n), min(n, 3)))
            goal_neg = sum(1 << f for f in pick.sample(range(n), min(n, trial % 3)))
            kept = derived.relevant(st, reach, goal, goal_neg)
            assert np.array_equal(kept, derived.relevant_numpy(st, reach, goal, goal_neg))
            assert not (kept & ~reach).any()
    assert clause_rows  # the disjunctive domain exercised the clause facts


@needs_fixpoint
def test_compiled_fixpoints_reject_bad_input():
    from avs_planner.cp import _fixpoint

    pre = np.array([[0, 5]], dtype=np.int64)  # fact 5 outside 3 slots
    add = np.array([[1]], dtype=np.int64)
    ok_pre = np.array([[0, 1]], dtype=np.int64)
    index = _fixpoint.index(1, ok_pre, 2, 3)
    assert np.frombuffer(index, np.int64).tolist() == [0, 1, 2, 2, 0, 0]
    with pytest.raises(ValueError, match="outside"):
        _fixpoint.reachable(1, pre, 2, add, 1, 3, 2, np.ones(3, bool), np.ones(1, bool), index)
    with pytest.raises(ValueError, match="bytes"):
        _fixpoint.reachable(2, ok_pre, 2, add, 1, 3, 2, np.ones(3, bool), np.ones(1, bool),
                            index)
    with pytest.raises(ValueError, match="not an index"):
        _fixpoint.reachable(1, ok_pre, 2, add, 1, 3, 2, np.ones(3, bool), np.ones(1, bool),
                            index[:-8])
    broken = np.frombuffer(index, np.int64).copy()
    broken[-1] = 7  # a row id outside the 1 row
    with pytest.raises(ValueError, match="outside"):
        _fixpoint.reachable(1, ok_pre, 2, add, 1, 3, 2, np.ones(3, bool), np.ones(1, bool),
                            broken.tobytes())
    out, bits = np.zeros((1, 2), np.int64), np.zeros((1, 1), "<u8")
    with pytest.raises(ValueError, match="outside"):
        _fixpoint.gather_rows(1, ok_pre, 2, 3, 1, np.array([1]), 1, None, out, bits)
    _fixpoint.gather_rows(1, np.array([[2, 0]]), 2, 3, 1, np.array([0]), 1, None, out, bits)
    assert out.tolist() == [[0, 2]] and bits.tolist() == [[0b101]]
    reached = _fixpoint.reachable(1, ok_pre, 2, add, 1, 3, 2,
                                  np.array([1, 0, 1], bool), np.ones(1, bool), index)
    assert list(reached) == [0]  # fact 1 is not reached
    reached = _fixpoint.reachable(1, ok_pre, 2, add, 1, 3, 2,
                                  np.array([1, 1, 0], bool), np.ones(1, bool), index)
    assert list(reached) == [1]


@pytest.mark.parametrize("compiled", [True, False])
def test_derived_rows_filled_in_any_order_match_a_fresh_sort(corridor, monkeypatch, compiled):
    from avs_planner.cp.derived import Derived
    from avs_planner.cp.structure import fact_matrix

    if compiled and derived._fixpoint is None:
        pytest.skip("compiled fixpoints not built")
    if not compiled:
        monkeypatch.setattr(derived, "_fixpoint", None)

    st = GroundingCache().structure(corridor, world_state(corridor.problem))
    n = len(st.facts)
    d = Derived(st)
    rng = np.random.default_rng(3)
    for _ in range(3):  # overlapping subsets: later calls reuse rows the earlier ones filled
        rows = np.sort(rng.choice(st.size, size=st.size // 3, replace=False))
        matrices = d.rows(rows)
        for source, m in zip((st.pre, st.pre_neg, st.add, st.delete), matrices, strict=True):
            expected = fact_matrix(source[rows], n, None)
            assert np.array_equal(m, expected)
    assert d.rows(np.zeros(0, dtype=np.int64))[0].shape[0] == 0
