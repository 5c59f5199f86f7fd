"""The relaxed merge (relaxed_merge.py): its compiled construction gives the numpy path's
RelaxedMerge field for field, and merging leaves h^max and h_add values unchanged."""

from __future__ import annotations

import dataclasses
import random

import numpy as np
import pytest

from avs_planner.cp import native, relaxed_merge
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.pddl import read_text
from bench.avs_generator import AvsSize, generate

from .conftest import AVS_DOMAIN

compiled = pytest.mark.skipif(relaxed_merge._fixpoint is None,
                              reason="compiled fixpoints not built")


def _both(monkeypatch, n_facts, args, pre, add, cost, probability, eligible):
    with monkeypatch.context() as m:
        m.setattr(relaxed_merge, "COMPILED", False)
        expected = relaxed_merge.build_merge(
            n_facts, pre, add,
            relaxed_merge.one_argument_groups(args, add, cost, probability, eligible))
    got = relaxed_merge.compiled_merge(n_facts, args, pre, add, cost, probability, eligible)
    return expected, got


def _assert_same(expected, got):
    for field in dataclasses.fields(expected):
        a, b = getattr(expected, field.name), getattr(got, field.name)
        if isinstance(a, np.ndarray):
            assert a.dtype.kind == np.asarray(b).dtype.kind and np.array_equal(a, b), field.name
        else:
            assert a == b, field.name


def _problem(size: AvsSize, seed: int):
    return read_text(AVS_DOMAIN.read_text(), generate(size, seed), "domain.pddl", "p.pddl")


@compiled
@pytest.mark.parametrize(("size", "seed"), [(AvsSize(8, 2, 2, 4), 0), (AvsSize(8, 2, 2, 4), 3),
                                            (AvsSize(20, 5, 4, 8), 0)])
def test_compiled_merge_equals_numpy_on_generated_problems(size, seed, monkeypatch):
    task = ground(_problem(size, seed), cache=GroundingCache())
    with monkeypatch.context() as m:
        m.setattr(relaxed_merge, "COMPILED", False)
        expected = relaxed_merge._merge_task(task)
    got = relaxed_merge._merge_task(task)
    assert got.n_merged > 0  # these problems have groups to merge
    _assert_same(expected, got)


@compiled
def test_compiled_merge_equals_numpy_on_the_corridor(corridor, monkeypatch):
    task = ground(corridor, cache=GroundingCache())
    with monkeypatch.context() as m:
        m.setattr(relaxed_merge, "COMPILED", False)
        expected = relaxed_merge._merge_task(task)
    _assert_same(expected, relaxed_merge._merge_task(task))


@compiled
@pytest.mark.parametrize("seed", range(40))
def test_compiled_merge_equals_numpy_on_random_tables(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 60))
    arity, n_facts = int(rng.integers(0, 4)), int(rng.integers(1, 12))
    wp, wa = int(rng.integers(0, 4)), int(rng.integers(0, 3))
    objects = int(rng.integers(1, 4))  # few objects: many rows differ in one argument

    def rows(width: int) -> np.ndarray:
        out = np.full((n, width), -1, dtype=np.int64)
        for i in range(n):
            facts = sorted(set(rng.integers(0, n_facts, size=int(rng.integers(0, width + 1)))
                               .tolist()))
            out[i, :len(facts)] = facts
        return out

    args = rng.integers(-1 if seed % 5 == 0 else 0, objects, size=(n, arity)).astype(np.int64)
    pre, add = rows(wp), rows(wa)
    if seed % 3 == 0 and n:  # duplicate remainders and identical actions
        pre[n // 2:] = pre[: n - n // 2]
        add[:] = add[0]
    cost = rng.choice([1.0, 2.0], size=n)
    probability = rng.choice([0.5, 1.0], size=n)
    eligible = (add >= 0).any(axis=1) & (rng.random(n) < 0.9) if wa else np.zeros(n, bool)
    _assert_same(*_both(monkeypatch, n_facts, args, pre, add, cost, probability, eligible))


@pytest.mark.skipif(not native.AVAILABLE, reason="native core not built")
@pytest.mark.parametrize("heuristic", ["hmax", "hadd"])
def test_merging_keeps_hmax_and_hadd(heuristic, monkeypatch):
    problem = _problem(AvsSize(8, 2, 2, 4), 1)
    task = ground(problem, cache=GroundingCache())
    rng = random.Random(3)
    states = set()
    while len(states) < 40:
        state = task.init
        for _ in range(rng.randint(0, 5)):
            state = rng.choice([a for a in task.actions if a.applicable(state)]).apply(state)
        states.add(state)
    states = sorted(states)
    merged = native.estimates(task, heuristic, 500.0, states)
    with monkeypatch.context() as m:
        m.setattr(relaxed_merge, "ENABLED", False)
        plain_task = ground(problem, cache=GroundingCache())
        assert relaxed_merge.merge_task(plain_task).n_merged == 0
        plain = native.estimates(plain_task, heuristic, 500.0, states)
    assert relaxed_merge.merge_task(task).n_merged > 0
    for (hc, hl, _), (pc, pl, _) in zip(merged, plain, strict=True):
        assert hc == pytest.approx(pc, rel=1e-12, abs=1e-9)
        assert hl == pytest.approx(pl, rel=1e-12, abs=1e-9)


@compiled
def test_one_large_group_among_many_small_ones(monkeypatch):
    # 300 actions differing in their second argument (one group), then 50 pairs
    big, pairs = 300, 50
    n = big + 2 * pairs
    args = np.zeros((n, 2), dtype=np.int64)
    args[:big, 1] = np.arange(big)
    args[big:, 0] = 1 + np.arange(2 * pairs) // 2
    args[big:, 1] = np.arange(2 * pairs) % 2
    n_facts = 400
    pre = np.full((n, 2), -1, dtype=np.int64)
    pre[:, 0] = 0  # common to all
    pre[:, 1] = 1 + np.arange(n) % 37  # remainders, some repeated within a group
    add = np.full((n, 1), -1, dtype=np.int64)
    add[:big, 0] = 390
    add[big:, 0] = 100 + np.arange(2 * pairs) // 2
    cost, probability = np.ones(n), np.full(n, 0.5)
    expected, got = _both(monkeypatch, n_facts, args, pre, add, cost, probability,
                          np.ones(n, dtype=bool))
    assert got.n_merged == 1 + pairs
    _assert_same(expected, got)
