"""Fact tables cut down to the facts a task uses (IPC tetris: 37,224 -> 928)."""

from __future__ import annotations

from unified_planning.engines.plan_validator import SequentialPlanValidator

from avs_planner.cp import compact as compact_module
from avs_planner.cp.anytime import GREEDY_WEIGHT, unit_cost
from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.cp.search import PlanStatus, SearchOptions, search
from avs_planner.pddl import read_files
from avs_planner.up_engine import to_up_plan
from tests.ipc import require_ipc


def _tetris():
    folder = require_ipc() / "tetris"
    return read_files(folder / "domain.pddl", folder / "instance-1.pddl")


def test_tetris_task_keeps_only_used_facts_and_the_same_actions(monkeypatch) -> None:
    pproblem = _tetris()
    small = ground(pproblem, cache=GroundingCache())
    monkeypatch.setattr(compact_module, "MIN_FACTS", 10**9)  # compaction off
    full = ground(pproblem, cache=GroundingCache())
    assert len(small.facts) < len(full.facts) // 10
    assert len(small.actions) == len(full.actions)
    for i in range(0, len(full.actions), 997):
        a, b = small.actions[i], full.actions[i]
        assert a.label == b.label
        for field in ("pre", "pre_neg", "add", "delete"):
            assert set(small.atoms_of(getattr(a, field))) == set(full.atoms_of(getattr(b, field)))
    assert set(small.atoms_of(small.goal)) == set(full.atoms_of(full.goal))
    assert set(small.atoms_of(small.init)) <= set(full.atoms_of(full.init))


def test_tetris_greedy_plan_is_valid() -> None:
    pproblem = _tetris()
    task = ground(pproblem)
    options = SearchOptions(weight=GREEDY_WEIGHT, lazy=True, preferred=False, patience=0,
                            timeout_s=60)
    result = search(unit_cost(task), options)
    assert result.status is PlanStatus.SOLVED
    check = SequentialPlanValidator().validate(
        pproblem.problem, to_up_plan(pproblem.problem, result.plan))
    assert check.status.name == "VALID"
    metric = pproblem.problem.quality_metrics[0]  # real costs, not the unit ones searched
    assert float(check.metric_evaluations[metric]) == result.cost > len(result.plan)
