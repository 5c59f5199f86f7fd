"""Helpful actions (preferred operators) and p = 0 pruning in grounding."""

from __future__ import annotations

from avs_planner.cp.grounding import ground
from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.planner import plan
from avs_planner.cp.search import SearchOptions


def test_ff_helpful_actions_are_applicable_relaxed_plan_actions(corridor):
    task = ground(corridor)
    estimator = get_heuristic("ff").factory(task, 500.0)
    hc, _ = estimator(task.init)
    helpful = estimator.helpful[task.init]
    assert helpful and hc > 0
    for i in helpful:
        assert task.actions[i].applicable(task.init)
    names = {task.actions[i].name for i in helpful}
    assert "move" in names or any(n.startswith("assume") for n in names)


def test_preferred_queue_keeps_the_plan_quality(corridor, make_random):
    for pproblem in [corridor] + [make_random(seed) for seed in range(20)]:
        on = plan(pproblem, SearchOptions(weight=2.0, preferred=True))
        off = plan(pproblem, SearchOptions(weight=2.0, preferred=False))
        assert on.status == off.status
        if on.solved:
            assert on.objective <= off.objective + 1e-9


def test_grounding_drops_actions_that_never_succeed(corridor):
    task = ground(corridor)
    assert task.actions
    assert all(a.probability > 0.0 for a in task.actions)
    assert [a.index for a in task.actions] == list(range(len(task.actions)))
