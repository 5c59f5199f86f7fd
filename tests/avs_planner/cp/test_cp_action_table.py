"""The grounder's lazy action table: the same actions as building them all, found by name
and arguments without building the others, and the symmetries read from its arrays."""

from __future__ import annotations

from dataclasses import replace

import pytest

from avs_planner.cp import native
from avs_planner.cp.action_table import ActionTable
from avs_planner.cp.grounding import GroundingCache, ground, world_state
from avs_planner.cp.symmetry import find_symmetries
from avs_planner.cp.task import WorldState
from avs_planner.errors import PlanningError
from avs_planner.pddl import read_text
from bench.avs_generator import AvsSize, generate

from .conftest import AVS_DOMAIN


@pytest.fixture(scope="module")
def generated():
    text = generate(AvsSize(8, 2, 2, 4), 0)
    return read_text(AVS_DOMAIN.read_text(), text, "domain.pddl", "p8.pddl")


def test_every_action_is_found_by_name_and_arguments(corridor, generated):
    for pproblem in (corridor, generated):
        task = ground(pproblem, cache=GroundingCache())
        assert isinstance(task.actions, ActionTable)
        for action in task.actions:
            assert task.action(action.name, action.args) == action
            assert task.action(action.name.upper(), [a.upper() for a in action.args]) == action


def test_lookup_misses_say_none(corridor):
    task = ground(corridor, cache=GroundingCache())
    move = next(a for a in task.actions if a.name == "move")
    assert task.action("move", move.args[:-1]) is None  # wrong arity
    assert task.action("move", (*move.args[:-1], "no-such-place")) is None
    assert task.action("no-such-action", move.args) is None
    # a ground action the grounder pruned (a move from a place to itself is not in the task)
    assert task.action("move", (move.args[0], move.args[0])) is None


def test_lazy_access_in_any_order_gives_the_same_actions(generated):
    cache = GroundingCache()
    state = world_state(generated.problem)
    eager = tuple(ground(generated, state, cache).actions)
    lazy = ground(generated, state, cache).actions
    picked = [len(lazy) - 1, 7, 0, 7]
    assert lazy.take(picked) == [eager[i] for i in picked]
    assert lazy[-1] == eager[-1] and lazy[3] == eager[3]
    assert lazy[2:9] == eager[2:9]
    assert tuple(lazy) == eager and lazy == eager
    assert all(a.index == i for i, a in enumerate(lazy))
    with pytest.raises(IndexError):
        lazy[len(eager)]


def test_symmetries_from_the_arrays_match_those_from_the_actions(generated, corridor):
    for pproblem in (corridor, generated):
        state = world_state(pproblem.problem)
        task = ground(pproblem, state, GroundingCache())
        from_arrays = find_symmetries(pproblem, state, task)
        plain = replace(task, actions=tuple(task.actions), arrays=None)
        from_actions = find_symmetries(pproblem, state, plain)
        assert from_arrays.checks  # both problems pre-allocate interchangeable objects
        assert dict(from_arrays.checks) == dict(from_actions.checks)
        assert from_arrays.groups == from_actions.groups
        if native.AVAILABLE:  # the array form packs to the same bytes as the mapping
            n_actions, n_facts = len(task.actions), len(task.facts)
            grouped = native.pack_symmetries(from_arrays, n_actions, n_facts)
            mapped = native.pack_symmetries(replace(from_arrays, grouped=None), n_actions,
                                            n_facts)
            assert [bytes(memoryview(x)) for x in grouped] == \
                [bytes(memoryview(x)) for x in mapped]


def test_no_object_is_assumed_on_itself(corridor, generated):
    """The AVS domain rules out `assume-obj-exists-on` with the support as the new object:
    no state allows it, but the relaxed heuristics would otherwise pay for those groundings."""
    for pproblem in (corridor, generated):
        task = ground(pproblem, cache=GroundingCache())
        on = [a for a in task.actions if a.name == "assume-obj-exists-on"]
        assert on  # the problems do assume objects on (virtual) supports
        assert all(a.args[1] != a.args[5] for a in on)


def test_initial_state_and_packed_task_are_kept_per_problem_and_task(corridor):
    cache = GroundingCache()
    state = cache.initial_state(corridor)
    assert cache.initial_state(corridor) is state
    assert state == world_state(corridor.problem)
    task = ground(corridor, cache=cache)
    if native.AVAILABLE:  # a replan from another state reuses the packed actions
        assert native.pack_task(task) is native.pack_task(task.with_init(0))
        changed = _with_a_probability_halved(state)
        assert native.pack_task(ground(corridor, changed, cache)) is not native.pack_task(task)


def _with_a_probability_halved(state: WorldState) -> WorldState:
    key = min(k for k, v in state.values.items() if 0.0 < v < 1.0)
    return WorldState(state.true_atoms, {**state.values, key: state.values[key] / 2})


def test_a_replan_reaching_the_same_actions_reuses_their_table(corridor):
    cache = GroundingCache()
    state = cache.initial_state(corridor)
    task = ground(corridor, state, cache)
    moved = WorldState((state.true_atoms - {("at", "place0")}) | {("at", "place1")},
                       state.values)
    replan = ground(corridor, moved, cache)
    assert replan.init != task.init
    assert replan.actions is task.actions and replan.arrays is task.arrays
    # the reused table is what grounding afresh gives
    fresh = ground(corridor, moved, GroundingCache())
    assert list(replan.actions) == list(fresh.actions)
    # another probability: a new table with the new value, and the old one is not changed
    halved = ground(corridor, _with_a_probability_halved(state), cache)
    assert halved.actions is not task.actions
    assert sorted(a.probability for a in halved.actions) != sorted(
        a.probability for a in task.actions)
    assert list(task.actions) == list(ground(corridor, state, GroundingCache()).actions)
    # dropped on request (the benchmark times replans that reach other actions with it)
    kept = ground(corridor, state, cache)
    assert ground(corridor, state, cache).actions is kept.actions
    structure = cache.structure(corridor, state)
    assert "evaluated" in structure.memo
    cache.forget_last_calls()
    assert "evaluated" not in structure.memo
    assert ground(corridor, state, cache).actions is not kept.actions


def test_a_replan_with_the_same_groups_reuses_the_symmetries(generated):
    cache = GroundingCache()
    state = cache.initial_state(generated)
    task = ground(generated, state, cache)
    first = find_symmetries(generated, state, task)
    assert first.groups  # the generated problem has interchangeable virtual objects
    replan = ground(generated, state, cache)
    again = find_symmetries(generated, state, replan)
    assert again is first
    if native.AVAILABLE:
        assert native._packed_symmetries(replan, again) is native._packed_symmetries(task, first)
    fresh_task = ground(generated, state, GroundingCache())
    assert find_symmetries(generated, state, fresh_task) == first
    # a state that splits a group: other symmetries for the same table
    virtual = first.groups[-1][0]
    assert virtual.startswith("new-object")
    split = WorldState(state.true_atoms | {("detected", virtual)}, state.values)
    other = find_symmetries(generated, split, task)
    assert other.groups != first.groups


def test_kept_evaluations_follow_the_numeric_values(corridor):
    cache = GroundingCache()
    state = cache.initial_state(corridor)
    ground(corridor, state, cache)
    # a value that a reachable action reads goes missing: the error, not the kept numbers
    key = min(k for k, v in state.values.items() if 0.0 < v < 1.0)
    missing = WorldState(state.true_atoms, {k: v for k, v in state.values.items() if k != key})
    with pytest.raises(PlanningError, match=r"no value for \(" + key[0]):
        ground(corridor, missing, cache)
    # and a changed value is read again, also after the error
    halved = ground(corridor, _with_a_probability_halved(state), cache)
    fresh = ground(corridor, _with_a_probability_halved(state), GroundingCache())
    assert list(halved.actions) == list(fresh.actions)


def test_a_few_rows_are_built_as_the_numpy_path_builds_them(monkeypatch):
    """Up to `_FEW_ROWS` rows (a plan's steps) are built from Python lists, more with numpy:
    both give the same actions, on every AVS example problem and IPC instance-1."""
    import random

    from avs_planner.cp import ground_structure

    from .conftest import avs_and_ipc_makers

    for name, make in avs_and_ipc_makers():
        task = ground(make(), cache=GroundingCache())
        table = getattr(task.actions, "table", task.actions)  # under a compacted fact table
        st, rows = table._st, table._rows.tolist()
        sample = random.Random(name).sample(rows, min(40, len(rows)))
        built = []
        for few in (ground_structure._FEW_ROWS, -1):
            monkeypatch.setattr(ground_structure, "_FEW_ROWS", few)
            st._rows.clear()
            built.append(st.rows(sample))
        assert built[0] == built[1], name
