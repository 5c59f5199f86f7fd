"""Deferred evaluation of the successors no helpful action reaches (the default on
probabilistic tasks with FF): fewer evaluations, the eager search's plans on the generated
AVS problems, a flush back to eager evaluation when h stalls, and the compiled core agrees
with the Python search on all of it."""

from __future__ import annotations

import importlib
from dataclasses import replace
from pathlib import Path

import pytest

from avs_planner.cp import native
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.heuristics import HEURISTICS
from avs_planner.cp.search import (
    DEFERRED,
    DEFERRED_UNHELPFUL,
    EAGER,
    STALL,
    SearchOptions,
    _lazy,
    search,
)
from avs_planner.cp.symmetry import find_symmetries
from avs_planner.pddl import read_text
from bench.avs_generator import AvsSize, generate

ROOT = Path(__file__).resolve().parents[3]
# the Python engine, whose loop reads STALL (the package exports a function named search)
search_module = importlib.import_module("avs_planner.cp.python_search")
OPTIONS = SearchOptions(reward=500.0, weight=2.0, heuristic="ff")


def generated(size: AvsSize, seed: int):
    pproblem = read_text((ROOT / "domains/avs/domain.pddl").read_text(), generate(size, seed),
                         "domain.pddl", f"{size.name}-s{seed}")
    cache = GroundingCache()
    state = cache.initial_state(pproblem)
    task = ground(pproblem, state, cache)
    return task, find_symmetries(pproblem, state, task)


def outcome(result) -> tuple:
    return (result.status, [s.label for s in result.plan], result.cost, result.probability,
            result.expanded, result.generated)


class _Counting:
    """An estimator that counts its calls and passes FF's helpful actions through."""

    def __init__(self, inner, calls: list[int]):
        self.inner, self.calls = inner, calls

    @property
    def helpful(self):
        return self.inner.helpful

    def __call__(self, state: int):
        self.calls.append(state)
        return self.inner(state)


def test_the_mode_follows_the_task_and_the_options():
    task, _ = generated(AvsSize(8, 2, 2, 4), 0)
    assert _lazy(task, OPTIONS) == DEFERRED_UNHELPFUL
    assert _lazy(task, replace(OPTIONS, lazy=False)) == EAGER
    assert _lazy(task, replace(OPTIONS, lazy=True)) == DEFERRED
    assert _lazy(task, replace(OPTIONS, preferred=False)) == EAGER  # no helpful actions
    assert _lazy(task, replace(OPTIONS, heuristic="hadd")) == EAGER
    assert _lazy(task, replace(OPTIONS, heuristic="hmax", weight=1.0)) == EAGER


@pytest.mark.parametrize("size", [AvsSize(8, 2, 2, 4), AvsSize(12, 3, 3, 6),
                                  AvsSize(20, 5, 4, 8)], ids=lambda s: s.name)
def test_same_objective_as_eager_evaluation(size):
    for seed in (0, 1, 2):
        task, symmetries = generated(size, seed)
        eager = search(task, replace(OPTIONS, lazy=False), symmetries)
        default = search(task, OPTIONS, symmetries)
        assert default.solved and eager.solved
        assert default.objective == pytest.approx(eager.objective)


def test_fewer_evaluations_than_eager(monkeypatch):
    task, symmetries = generated(AvsSize(20, 5, 4, 8), 1)
    counts = {}
    spec = HEURISTICS["ff"]
    for lazy in (False, None):
        calls: list[int] = []
        monkeypatch.setitem(HEURISTICS, "ff", replace(
            spec, factory=lambda t, r, calls=calls: _Counting(spec.factory(t, r), calls)))
        result = search(task, replace(OPTIONS, lazy=lazy, engine="python"), symmetries)
        assert result.solved
        counts[lazy] = len(calls)
    assert counts[None] * 3 < counts[False]


def test_a_stall_flushes_the_deferred_nodes(monkeypatch):
    """20-place seed 0: the helpful actions lead onto a plateau (view cones of labels nobody
    looks for); without the flush the search exhausts it (200,000 expansions, no plan),
    with it the node that assumes the object in the right room gets its own estimate."""
    task, symmetries = generated(AvsSize(20, 5, 4, 8), 0)
    python = search(task, replace(OPTIONS, engine="python"), symmetries)
    assert python.solved and python.expanded > STALL
    eager = search(task, replace(OPTIONS, lazy=False, engine="python"), symmetries)
    assert python.objective == pytest.approx(eager.objective)
    if native.AVAILABLE:
        for threads in (1, 2):
            compiled = search(task, replace(OPTIONS, engine="native", threads=threads),
                              symmetries)
            assert outcome(compiled) == outcome(python)
    monkeypatch.setattr(search_module, "STALL", 10**9)  # never flush (Python engine only)
    stuck = search(task, replace(OPTIONS, engine="python", node_limit=3000), symmetries)
    assert not stuck.solved


@pytest.mark.skipif(not native.AVAILABLE, reason="native core not built")
@pytest.mark.parametrize("size", [AvsSize(8, 2, 2, 4), AvsSize(12, 3, 3, 6)],
                         ids=lambda s: s.name)
def test_compiled_and_python_agree(size):
    for seed in (0, 1, 2):
        task, symmetries = generated(size, seed)
        python = search(task, replace(OPTIONS, engine="python"), symmetries)
        compiled = search(task, replace(OPTIONS, engine="native"), symmetries)
        assert outcome(compiled) == outcome(python)
