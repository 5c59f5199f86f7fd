"""The episode builds its problems on the project's own model (`pddl.lite`), so an episode
never imports unified-planning; UP's problem of the same state (asked for by `.problem`) is
the same problem: printed alike, ground alike and planned alike."""

from __future__ import annotations

from dataclasses import replace

from avs_planner.cp.continual import ContinualPlanner
from avs_planner.cp.search import SearchOptions
from avs_planner.pddl import ProbabilisticProblem
from avs_planner.pddl.lite import is_lite
from tests.avs_planner.pddl.test_pddl_fast_reader import canonical
from tests.avs_planner.pddl.test_pddl_lite import grounded

OPTIONS = SearchOptions(weight=3.0, heuristic="hadd", timeout_s=None)


def on_up(read: ProbabilisticProblem) -> ProbabilisticProblem:
    return replace(read, model=read.problem, success=read.up_success)


def test_built_problems_are_lite_and_alike_in_both_models(corridor_mind) -> None:
    _, builder, _ = corridor_mind
    state = builder.build()
    for fast in (state.problem(), state.skeleton()):
        assert is_lite(fast.model)
        up = on_up(fast)
        assert not is_lite(up.model)
        assert canonical(fast.model) == canonical(up.model)
        assert {k: str(v) for k, v in fast.success.items()} == {
            k: str(v) for k, v in up.success.items()}
        assert grounded(fast) == grounded(up)  # the skeleton alike refused: no :init
    assert grounded(state.problem())[0] != "raised"


def test_built_problems_plan_alike_in_both_models(corridor_mind) -> None:
    _, builder, _ = corridor_mind
    state = builder.build()
    for fast in (state.problem(), state.skeleton()):
        ours = ContinualPlanner(fast, OPTIONS).replan(state.world_state())
        theirs = ContinualPlanner(on_up(fast), OPTIONS).replan(state.world_state())
        assert ours.solved
        assert [s.label for s in ours.plan] == [s.label for s in theirs.plan]
        assert (ours.cost, ours.probability) == (theirs.cost, theirs.probability)
