"""Grounding: bitsets, static filtering, CNF of quantified conditions, cache reuse, errors."""

from __future__ import annotations

import pytest
from unified_planning.shortcuts import (
    BoolType,
    Fluent,
    InstantaneousAction,
    Or,
    Problem,
    UserType,
)

from avs_planner.cp.grounding import GroundingCache, ground, world_state
from avs_planner.errors import PlanningError
from avs_planner.pddl.model import ProbabilisticProblem


def test_corridor_grounding_uses_statics_and_probabilities(corridor):
    task = ground(corridor, cache=GroundingCache())
    moves = sorted(a.label for a in task.actions if a.name == "move")
    # only connected pairs are grounded (connected is static)
    assert "(move place0 place3)" not in moves
    assert "(move place0 place1)" in moves
    assume = task.action("assume-leads-to-room", ["place1", "kitchen", "new-room1"])
    assert assume.probability == pytest.approx(0.6) and assume.assumptive
    assert task.action("move", ["place0", "place1"]).cost == 3
    # p = 0 assumptions are dropped: place1 never leads to a room of p 0
    assert task.action("assume-category", ["room1", "kitchen"]) is None


def test_forall_precondition_becomes_clauses(corridor):
    task = ground(corridor, cache=GroundingCache())
    cones = task.action("createviewcones-in", ["table", "room1"])
    state = task.init
    # room1 has unvisited placeholders place1/place3: not yet applicable
    assert not cones.applicable(state)
    visited = task.state_of([("visited", "place1"), ("visited", "place3")])
    assert cones.applicable(state | visited)


def test_cache_reuses_structure_across_states(corridor):
    cache = GroundingCache()
    state = world_state(corridor.problem)
    ground(corridor, state, cache)
    misses = cache.misses
    moved = state.updated(add=[("at", "place2")], delete=[("at", "place0")],
                          values={("p-placeholder-category", "place1", "kitchen"): 0.2})
    task = ground(corridor, moved, cache)
    assert cache.misses == misses  # same domain, objects and static atoms: no regrounding
    assume = task.action("assume-leads-to-room", ["place1", "kitchen", "new-room1"])
    assert assume.probability == pytest.approx(0.2)
    assert task.init & task.state_of([("at", "place2")])


def test_unsupported_effects_are_named():
    thing = UserType("thing")
    flag = Fluent("flag", BoolType(), x=thing)
    action = InstantaneousAction("toggle", x=thing)
    other = Fluent("other", BoolType(), x=thing)
    x = action.parameter("x")
    action.add_effect(flag(x), True, condition=Or(flag(x), other(x)))
    problem = Problem("p")
    problem.add_fluent(flag, default_initial_value=False)
    problem.add_fluent(other, default_initial_value=False)
    problem.add_action(action)
    problem.add_goal(flag(problem.add_object("a", thing)))
    with pytest.raises(PlanningError, match="toggle: conditional effect .* only conjunctions"):
        ground(ProbabilisticProblem(problem), cache=GroundingCache())
