"""The cached grounding structure: complex conditions grounded once per distinct binding of
the parameters they read (results must not leak between bindings), and the two ways (dense
table, sorted search) of numbering atom codes as fact ids and of testing static atoms agreeing,
and decoding many codes at once (sorted internally) keeping the caller's order."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from avs_planner.cp.bindings import code_set as _code_set
from avs_planner.cp.encoding import AtomSpace
from avs_planner.cp.grounding import GroundingCache, ground, world_state
from avs_planner.cp.structure import _PAD_NONE, _PAD_TRUE, _fact_numbering
from avs_planner.errors import PlanningError
from avs_planner.pddl import read_text
from bench.avs_generator import AvsSize, generate

from .conftest import AVS_DOMAIN

DOMAIN = """
(define (domain looks)
  (:requirements :strips :typing :negative-preconditions :equality
                 :disjunctive-preconditions :quantified-preconditions)
  (:types room thing)
  (:predicates (near ?a - room ?t - thing) (link ?a - room ?b - room)
               (at ?t - thing ?r - room) (lit ?r - room) (dark ?r - room) (seen ?t - thing))
  (:action look
    :parameters (?a - room ?x - thing ?b - room)
    :precondition (and (forall (?t - thing) (imply (near ?a ?t) (at ?t ?b)))
                       (or (lit ?b) (dark ?b))
                       (exists (?r - room) (link ?a ?r)))
    :effect (seen ?x))
  (:action change
    :parameters (?t - thing ?r - room)
    :effect (and (at ?t ?r) (lit ?r) (dark ?r))))
"""

PROBLEM = """
(define (problem looks1) (:domain looks)
  (:objects r1 r2 r3 - room t1 t2 t3 - thing)
  (:init (near r1 t1) (near r1 t2) (near r2 t3) (link r1 r2) (link r2 r3) (at t1 r1))
  (:goal (seen t1)))
"""

NEAR = {"r1": ("t1", "t2"), "r2": ("t3",), "r3": ()}
LINKED = {"r1", "r2"}  # r3 links nowhere: its rows have an empty clause and are dropped


def test_complex_conditions_do_not_mix_bindings():
    pproblem = read_text(DOMAIN, PROBLEM, "domain.pddl", "problem.pddl")
    structure = GroundingCache().structure(pproblem, world_state(pproblem.problem))
    facts, n = structure.facts, len(structure.facts)
    (block,) = (b for b in structure.blocks if b.schema.name == "look")
    got = {}
    for k, row in enumerate(range(block.start, block.stop)):
        args = tuple(structure.space.names[int(block.columns[p][k])]
                     for p in block.schema.params)
        pre = {facts[i] for i in structure.pre[row].tolist() if i < n}
        clauses = {tuple(tuple(facts[i] for i in side) for side in clause)
                   for clause in structure.clauses.get(row, ())}
        got[args] = (pre, clauses)
    expected = {
        (a, x, b): ({("at", t, b) for t in NEAR[a]}, {((("dark", b), ("lit", b)), ())})
        for a, x, b in itertools.product(("r1", "r2", "r3"), ("t1", "t2", "t3"),
                                         ("r1", "r2", "r3"))
        if a in LINKED
    }
    assert got == expected


def test_dense_and_sorted_fact_numbering_agree():
    rng = np.random.default_rng(3)
    arrays = [rng.integers(0, 500, size=(40, 3)), rng.integers(0, 500, size=(7, 5))]
    arrays[0][::4, 2] = _PAD_TRUE
    arrays[1][::3, 0] = _PAD_NONE
    extra = np.array([499, 0, 17], dtype=np.int64)
    dense_codes, dense = _fact_numbering(500, arrays, extra)
    sorted_codes, by_search = _fact_numbering(10**15, arrays, extra)  # too big for a table
    expected = np.unique(np.concatenate([a[a >= 0] for a in arrays] + [extra]))
    assert dense_codes.tolist() == sorted_codes.tolist() == expected.tolist()
    n = len(expected)
    for array in arrays:
        want = np.where(array == _PAD_TRUE, n, np.where(array == _PAD_NONE, n + 1,
                                                          np.searchsorted(expected, array)))
        assert dense(array).tolist() == by_search(array).tolist() == want.tolist()


def test_dense_and_sorted_code_sets_agree():
    codes = np.array([7, 3, 499, 3, 0], dtype=np.int64)
    queries = np.arange(500, dtype=np.int64)
    dense = _code_set(codes, 500)(queries)
    by_search = _code_set(codes, 10**15)(queries)  # too big for a table
    assert dense.tolist() == by_search.tolist() == np.isin(queries, codes).tolist()


def test_decode_many_keeps_input_order_and_one_tuple_per_atom():
    pproblem = read_text(DOMAIN, PROBLEM, "domain.pddl", "problem.pddl")
    space = AtomSpace(pproblem.problem)
    atoms = [("seen", "t2"), ("at", "t3", "r1"), ("link", "r2", "r1"), ("at", "t1", "r3"),
             ("seen", "t2"), ("dark", "r2")]
    codes = np.array([space.encode(a) for a in atoms], dtype=np.int64)  # unsorted, a repeat
    first = space.decode(int(codes[1]))
    decoded = space.decode_many(codes)
    assert decoded == atoms
    assert decoded[1] is first and decoded[0] is decoded[4]
    assert space.decode_many(codes[:0]) == []


NUMERIC_OR_DOMAIN = """
(define (domain numor)
  (:requirements :strips :typing :numeric-fluents :disjunctive-preconditions)
  (:types thing)
  (:predicates (p ?t - thing) (done ?t - thing))
  (:functions (level ?t - thing))
  (:action act :parameters (?t - thing)
    :precondition (or (p ?t) (> (level ?t) 1))
    :effect (done ?t)))
"""

NUMERIC_OR_PROBLEM = """
(define (problem numor1) (:domain numor)
  (:objects a - thing)
  (:init (= (level a) 2))
  (:goal (done a)))
"""


def test_an_unsupported_condition_inside_a_disjunction_is_named():
    pproblem = read_text(NUMERIC_OR_DOMAIN, NUMERIC_OR_PROBLEM, "d.pddl", "p.pddl")
    # the reader reads it; its check found the condition, and the planner stops there
    with pytest.raises(PlanningError, match=r"^d\.pddl:8:30: the numeric condition "
                       r"\(> \(level \?t\) 1\) in action 'act' is not supported"):
        ground(pproblem, cache=GroundingCache())
    # without the check's finding, the grounder names it, with the action and its position
    with pytest.raises(PlanningError, match=r"^d\.pddl:7:12: action act: unsupported "
                       r"condition \(1 < level\(t\)\) \(a numeric comparison"):
        ground(replace(pproblem, not_grounded=()), cache=GroundingCache())


@pytest.mark.parametrize("size", ["small", "large"])
def test_encode_all_gives_the_codes_encode_gives(size):
    """Small groups of atoms are encoded one by one, large ones on arrays (a 20-place AVS
    problem has 192 `p-obj-on` values)."""
    if size == "small":
        pproblem = read_text(DOMAIN, PROBLEM, "d.pddl", "p.pddl")
    else:
        pproblem = read_text(AVS_DOMAIN.read_text(), generate(AvsSize(20, 5, 4, 8), 0),
                             "d.pddl", "p.pddl")
    space = AtomSpace(pproblem.problem)
    state = world_state(pproblem.problem)
    atoms = [*state.true_atoms, *state.values, ("no-such-fluent", "x"),
             (next(iter(state.true_atoms))[0], "no-such-object"), ("at",)]
    expected = sorted(c for c in map(space.encode, atoms) if c is not None)
    assert sorted(space.encode_all(atoms).tolist()) == expected
    assert len(expected) == len(state.true_atoms) + len(state.values)
    assert space.encode_all([]).tolist() == []
