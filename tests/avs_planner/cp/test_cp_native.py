"""The compiled search core returns what the Python search returns: same plan, cost,
probability, status and the same expanded/generated counts (it is a port, float for float)."""

from __future__ import annotations

import math
import os
import random
from dataclasses import replace
from pathlib import Path

import pytest

from avs_planner.cp import native
from avs_planner.cp.grounding import ground, world_state
from avs_planner.cp.relaxed_merge import merge_task
from avs_planner.cp.search import PlanStatus, SearchOptions, search
from avs_planner.cp.symmetry import NO_SYMMETRIES, find_symmetries
from avs_planner.cp.task import GroundAction, GroundTask
from avs_planner.errors import PlanningError
from tests.ipc import require_ipc

ROOT = Path(__file__).resolve().parents[3]
needs_native = pytest.mark.skipif(not native.AVAILABLE, reason="native core not built")


def test_the_native_core_is_built():
    """CI must not fall back silently: set AVS_ALLOW_NO_NATIVE=1 where no compiler exists."""
    if os.environ.get("AVS_ALLOW_NO_NATIVE") == "1":
        pytest.skip("AVS_ALLOW_NO_NATIVE=1")
    assert native.AVAILABLE, "avs_planner.cp._native did not import: run `pip install -e .`"


def outcome(result):
    return (result.status, [s.label for s in result.plan], result.cost, result.probability,
            result.expanded, result.generated)


def same(task, options, symmetries=NO_SYMMETRIES):
    """Both engines on one task; asserts equal outcomes and returns the native result."""
    py = search(task, replace(options, engine="python"), symmetries)
    c = search(task, replace(options, engine="native"), symmetries)
    assert py.extra["engine"] == "python" and c.extra["engine"] == "native"
    assert outcome(c) == outcome(py), options
    return c


def _with(action: GroundAction, **changes) -> GroundAction:
    """A copy with some fields changed (GroundAction is a dataclass or a named tuple)."""
    if hasattr(action, "_replace"):
        return action._replace(**changes)
    return replace(action, **changes)


def random_ground_task(seed: int, n_facts: int = 70, n_actions: int = 40) -> GroundTask:
    """A random task built directly as bitsets: > 64 facts (two words per state), forall-imply
    style clauses (unit and wider), probabilities, zero costs; exercises what PDDL tasks of the
    other generator do not."""
    rng = random.Random(seed)
    facts = tuple((f"f{i}",) for i in range(n_facts))
    hot = rng.sample(range(n_facts), 12)  # a small core so that actions interact
    # odd seeds: fractional values (summation order shows); even: few values (ties show)
    costs = [0.0, 1.0, 0.1, 0.7, 2.3] if seed % 2 else [0.0, 1.0, 2.0]
    probabilities = [1.0, 0.9, 0.6, 0.3, 0.77] if seed % 2 else [1.0, 0.5]

    def bits(k: int) -> tuple[int, tuple[int, ...]]:
        ids = tuple(sorted(rng.sample(hot, k)))
        return sum(1 << i for i in ids), ids

    actions = []
    for i in range(n_actions):
        pre, pre_ids = bits(rng.randint(0, 2))
        pre_neg = bits(rng.randint(0, 1))[0] & ~pre
        add, add_ids = bits(rng.randint(1, 2))
        delete = bits(rng.randint(0, 2))[0] & ~add
        clauses = []
        for _ in range(rng.choice([0, 0, 1, 2])):
            pos, neg = bits(rng.choice([1, 1, 2]))[0], bits(rng.randint(1, 2))[0]
            clauses.append((pos, neg & ~pos))
        actions.append(GroundAction(
            index=i, name=f"a{i}", args=(), pre=pre, pre_neg=pre_neg, add=add, delete=delete,
            cost=rng.choice(costs), probability=rng.choice(probabilities),
            pre_facts=pre_ids, add_facts=add_ids,
            clauses=tuple(c for c in clauses if c[1]),
        ))
    init = bits(3)[0]
    goal = bits(2)[0]
    return GroundTask(facts, {f: i for i, f in enumerate(facts)}, tuple(actions), init, goal,
                      goal_neg=bits(1)[0] & ~goal)


def random_walk_states(task: GroundTask, rng: random.Random, n: int) -> list[int]:
    states, state = [task.init], task.init
    while len(states) < n:
        moves = [a for a in task.actions if a.applicable(state)]
        state = rng.choice(moves).apply(state) if moves and rng.random() < 0.9 else task.init
        states.append(state)
    return states


@needs_native
@pytest.mark.parametrize("heuristic", ["ff", "hadd", "hmax", "blind"])
def test_estimates_are_bit_identical_to_heuristics_py(heuristic):
    """Each estimate (and FF's helpful actions) equals the Python estimator's, float for float:
    fractional costs and probabilities make any change in summation order show."""
    from avs_planner.cp.heuristics import get_heuristic

    rng = random.Random(7)
    tasks = [random_ground_task(seed) for seed in range(30)] + [_avs("corridor")[0]]
    for task in tasks:
        states = random_walk_states(task, rng, 40)
        estimator = get_heuristic(heuristic).factory(task, 50.0)
        for state, (hc, hl, helpful) in zip(
                states, native.estimates(task, heuristic, 50.0, states), strict=True):
            assert (hc, hl) == estimator(state)
            if heuristic == "ff" and hc != math.inf:
                assert frozenset(helpful) == estimator.helpful[state]


@needs_native
@pytest.mark.parametrize("heuristic", ["ff", "hadd", "hmax", "blind"])
def test_random_problems_every_heuristic_weight_and_lazy(heuristic, make_random):
    for seed in range(25):
        task = ground(make_random(seed, n_fluents=6, n_actions=10))
        for weight in (1.0, 2.0, 3.0):
            for lazy in (None, True, False):
                same(task, SearchOptions(reward=100.0, heuristic=heuristic, weight=weight,
                                         lazy=lazy))


@needs_native
@pytest.mark.parametrize("heuristic", ["ff", "hadd", "hmax", "blind"])
def test_random_bitset_tasks_with_clauses(heuristic):
    solved = 0
    for seed in range(16):
        task = random_ground_task(seed)
        for weight, lazy, preferred in ((1.0, None, True), (2.0, True, True), (3.0, False, False)):
            result = same(task, SearchOptions(reward=50.0, heuristic=heuristic, weight=weight,
                                              lazy=lazy, preferred=preferred, node_limit=250))
            solved += result.solved
    assert solved >= 8


@needs_native
def test_limits_thresholds_and_unsolvable(make_random):
    statuses = set()
    for seed in range(25):
        task = ground(make_random(seed, n_fluents=6, n_actions=10))
        for options in (SearchOptions(reward=100.0, min_success=0.5),
                        SearchOptions(reward=100.0, min_success=0.95, heuristic="hmax"),
                        SearchOptions(reward=100.0, node_limit=1),
                        SearchOptions(reward=100.0, node_limit=3, heuristic="hadd")):
            statuses.add(same(task, options).status)
        unreachable = replace(task, goal=task.goal | 1 << len(task.facts) - 1,
                              goal_neg=1 << len(task.facts) - 1)
        statuses.add(same(unreachable, SearchOptions(reward=100.0)).status)
    assert {PlanStatus.SOLVED, PlanStatus.NODE_LIMIT, PlanStatus.UNSOLVABLE,
            PlanStatus.NO_PLAN_ABOVE_THRESHOLD} <= statuses


def _avs(name: str):
    from avs_planner.pddl import read_files

    pproblem = read_files(ROOT / "domains/avs/domain.pddl",
                          ROOT / f"domains/avs/problems/{name}.pddl")
    state = world_state(pproblem.problem)
    task = ground(pproblem, state)
    return task, find_symmetries(pproblem, state, task)


@needs_native
@pytest.mark.parametrize("name", ["corridor", "room3-kitchen", "table-known"])
def test_avs_problems_with_and_without_symmetry(name):
    task, symmetries = _avs(name)
    assert symmetries.checks or name == "table-known"
    runs = [("ff", 2.0, None), ("ff", 3.0, True), ("hadd", 2.0, None), ("hmax", 1.0, None)]
    for heuristic, weight, lazy in runs:
        options = SearchOptions(reward=500.0, heuristic=heuristic, weight=weight, lazy=lazy,
                                node_limit=200)
        result = same(task, options, symmetries)
        assert result.status in (PlanStatus.SOLVED, PlanStatus.NODE_LIMIT)
    same(task, SearchOptions(reward=500.0, node_limit=600))  # no symmetry pruning
    same(task, SearchOptions(reward=500.0, min_success=0.5, node_limit=1500), symmetries)


@needs_native
def test_replans_reuse_the_packed_actions():
    task, symmetries = _avs("corridor")
    first = same(task, SearchOptions(reward=500.0), symmetries)
    packed = native.pack_task(task)
    state = task.init
    for step in first.plan[:4]:  # replan from states along the plan
        state = task.action(step.name, step.args).apply(state)
        later = task.with_init(state)
        assert native.pack_task(later) is packed
        same(later, SearchOptions(reward=500.0), symmetries)


@needs_native
@pytest.mark.parametrize("domain", ["blocks", "elevators", "gripper", "logistics"])
def test_first_ipc_instance(domain):
    from unified_planning.io import PDDLReader

    from avs_planner.pddl.model import ProbabilisticProblem

    folder = require_ipc() / domain
    problem = PDDLReader().parse_problem(str(folder / "domain.pddl"),
                                         str(folder / "instance-1.pddl"))
    task = ground(ProbabilisticProblem(problem))
    assert same(task, SearchOptions(weight=2.0)).solved
    same(task, SearchOptions(weight=1.0, heuristic="hmax", node_limit=100))


@needs_native
def test_timeout_and_result_shape():
    task, symmetries = _avs("room3-kitchen")
    timed = search(task, SearchOptions(heuristic="blind", timeout_s=1e-9, engine="native"))
    assert timed.status is PlanStatus.TIMEOUT and timed.plan == ()
    auto = search(task, SearchOptions(reward=500.0), symmetries)
    assert auto.extra["engine"] == "native" and auto.as_json()["status"] == "solved"


def test_engine_option_is_checked(monkeypatch):
    with pytest.raises(PlanningError, match="unknown engine"):
        SearchOptions(engine="fortran").check()
    monkeypatch.setattr(native, "AVAILABLE", False)
    with pytest.raises(PlanningError, match="not built"):
        SearchOptions(engine="native").check()
    assert SearchOptions(engine="auto").engine_used == "python"


@needs_native
def test_bad_tasks_are_errors_not_crashes():
    task = random_ground_task(0)
    outside = _with(task.actions[0], pre=1 << len(task.facts) + 3)
    with pytest.raises(PlanningError, match="outside"):
        search(replace(task, actions=(outside, *task.actions[1:])),
               SearchOptions(engine="native"))
    shuffled = (task.actions[1], task.actions[0], *task.actions[2:])
    with pytest.raises(PlanningError, match="index"):
        search(replace(task, actions=shuffled), SearchOptions(engine="native"))
    with pytest.raises(PlanningError, match="outside"):
        search(task.with_init(1 << 500), SearchOptions(engine="native"))
    with pytest.raises(ValueError, match="native"):
        native._native.Task(3, 1, *([b""] * 14), 3, 0, *([b""] * 9))
    args = (*native.task_args(task), *native.merge_args(merge_task(task)))
    native._native.Task(*args)  # well formed
    with pytest.raises(ValueError, match="merge"):
        native._native.Task(*args[:16], len(task.facts) - 1, *args[17:])


@needs_native
def test_packed_rows_are_checked_by_the_core():
    """The core builds an action's non-zero words from packed fact ids (`packed_rows`): a
    fact id outside the task, or offsets that are not a CSR over the actions, is a
    ValueError naming the table, never memory read out of bounds."""
    task = random_ground_task(1)
    args = list(native.task_args(task))
    n_facts, n_actions = args[0], args[1]
    offsets = [0] * (n_actions + 1)
    offsets[1:] = [1] * n_actions  # action 0 adds one fact, the others none
    args[4] = native.packed_rows(offsets, [n_facts])  # add: a fact past the last
    with pytest.raises(ValueError, match="add fact .* outside"):
        native._native.Task(*args, *native.merge_args(merge_task(task)))
    args[4] = native.packed_rows([0] * n_actions, [])  # one offset short
    with pytest.raises(ValueError, match="add is not a packed CSR"):
        native._native.Task(*args, *native.merge_args(merge_task(task)))
    args[4] = native.packed_rows([0, 2] + [1] * (n_actions - 1), [0, 1])  # offsets decrease
    with pytest.raises(ValueError, match="add is not a packed CSR"):
        native._native.Task(*args, *native.merge_args(merge_task(task)))


@needs_native
@pytest.mark.slow
def test_generated_avs_problem_and_many_random_tasks():
    """Longer sweep: a generated 8-place AVS problem (dual queue used for hundreds of
    expansions) and more random tasks."""
    pproblem = _generated_p8()
    state = world_state(pproblem.problem)
    task = ground(pproblem, state)
    symmetries = find_symmetries(pproblem, state, task)
    for heuristic, weight in (("ff", 2.0), ("ff", 1.0), ("hadd", 3.0)):
        same(task, SearchOptions(reward=500.0, heuristic=heuristic, weight=weight), symmetries)
    for seed in range(16, 200):
        for heuristic in ("ff", "hadd", "hmax"):
            same(random_ground_task(seed), SearchOptions(reward=50.0, heuristic=heuristic,
                                                         node_limit=1000))


@needs_native
def test_avs_plan_engine_flag(capsys):
    import json

    from avs_planner.cli import main

    args = ["plan", str(ROOT / "domains/avs/domain.pddl"),
            str(ROOT / "domains/avs/problems/table-known.pddl"), "--json"]
    outputs = []
    for engine in ("python", "native"):
        assert main([*args, "--engine", engine]) == 0
        out = json.loads(capsys.readouterr().out)
        outputs.append((out["plan"], out["expanded"], out["cost"], out["probability"]))
    assert outputs[0] == outputs[1]


@needs_native
@pytest.mark.parametrize("name", ["corridor", "room3-kitchen"])
def test_packing_from_the_grounder_arrays_equals_packing_from_actions(name):
    task, _ = _avs(name)
    assert task.arrays is not None
    fast, slow = native.task_arrays(task), native.task_args(task)
    assert len(fast) == len(slow)
    for a, b in zip(fast, slow, strict=True):
        assert (a == b) if isinstance(a, int) else bytes(memoryview(a)) == bytes(memoryview(b))


def _generated_p8():
    from avs_planner.pddl import read_text
    from bench.avs_generator import AvsSize, generate

    domain = (ROOT / "domains/avs/domain.pddl").read_text()
    return read_text(domain, generate(AvsSize(8, 2, 2, 4), 0), "domain.pddl", "p8")


class _Alarm(Exception):
    pass


@needs_native
@pytest.mark.skipif(not hasattr(__import__("signal"), "setitimer"), reason="no setitimer")
def test_a_long_native_search_lets_signals_through():
    """The GIL is released during the search; signal handlers (Ctrl-C) still run."""
    import signal
    import time

    task = ground(_generated_p8())  # blind search at w = 1 runs for many seconds here

    def alarm(signum, frame):
        raise _Alarm

    previous = signal.signal(signal.SIGALRM, alarm)
    start = time.perf_counter()
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        with pytest.raises(_Alarm):
            search(task, SearchOptions(heuristic="blind", weight=1.0, engine="native",
                                       timeout_s=60.0))
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    assert time.perf_counter() - start < 30.0


def test_ff_supporter_ties_follow_the_python_action_order():
    """Two supporters of the goal complete on the same pop with equal cost; Python keeps the
    lower index. The C core shares counters between actions with equal preconditions (a0 and
    a2 here), so it must still pick a1: the helpful actions show which one it took."""
    x, p, q, f, g, z = range(6)

    def action(i, pre, add, cost):
        return GroundAction(index=i, name=f"a{i}", args=(), pre=sum(1 << b for b in pre),
                            pre_neg=0, add=1 << add, delete=0, cost=cost, probability=1.0,
                            pre_facts=tuple(pre), add_facts=(add,))

    actions = (action(0, (f, q), z, 1.0), action(1, (f, p), g, 1.0), action(2, (f, q), g, 1.0),
               action(3, (), p, 0.0), action(4, (x,), q, 0.0), action(5, (), f, 1.0))
    facts = tuple((name,) for name in "xpqfgz")
    task = GroundTask(facts, {a: i for i, a in enumerate(facts)}, actions, 1 << x, 1 << g)
    from avs_planner.cp.heuristics import get_heuristic

    estimator = get_heuristic("ff").factory(task, 10.0)
    assert estimator(task.init) == (2.0 + 1.0 + 2.0, 0.0)
    assert estimator.helpful[task.init] == {3, 5}
    if native.AVAILABLE:
        ((hc, hl, helpful),) = native.estimates(task, "ff", 10.0, [task.init])
        assert (hc, hl) == (5.0, 0.0) and set(helpful) == {3, 5}


@needs_native
def test_symmetry_packing_does_not_depend_on_the_order_of_checks():
    task, symmetries = _avs("corridor")
    shuffled = dict(reversed(list(symmetries.checks.items())))
    n_actions, n_facts = len(task.actions), len(task.facts)
    assert native.pack_symmetries(replace(symmetries, checks=shuffled), n_actions, n_facts) \
        == native.pack_symmetries(symmetries, n_actions, n_facts)
    same(task, SearchOptions(reward=500.0), replace(symmetries, checks=shuffled))


@needs_native
@pytest.mark.parametrize("heuristic", ["ff", "hadd", "hmax"])
def test_a_second_evaluating_thread_changes_nothing(heuristic, make_random):
    """threads=2 evaluates each expansion's new states on a worker thread as well (their
    estimates are recorded in the order they were generated): the same plan and counts as
    the Python search and as one thread, clauses, symmetries and helpful actions included."""
    tasks = [(random_ground_task(seed), NO_SYMMETRIES) for seed in range(12)]
    tasks += [(ground(make_random(seed, n_fluents=6, n_actions=10)), NO_SYMMETRIES)
              for seed in range(8)]
    tasks += [_avs("corridor"), _avs("room3-kitchen")]
    for task, symmetries in tasks:
        for weight in (1.0, 2.0):
            options = SearchOptions(reward=100.0, heuristic=heuristic, weight=weight,
                                    lazy=False, threads=2)
            two = same(task, options, symmetries)
            one = search(task, replace(options, threads=1, engine="native"), symmetries)
            assert outcome(one) == outcome(two)


@needs_native
def test_threads_on_a_20_place_problem():
    """The size the automatic choice gives two threads: 1, 2 and automatic agree."""
    from avs_planner.pddl import read_text
    from bench.avs_generator import AvsSize, generate

    text = generate(AvsSize(20, 5, 4, 8), 1)
    pproblem = read_text((ROOT / "domains/avs/domain.pddl").read_text(), text, "domain", "p20")
    state = world_state(pproblem.problem)
    task = ground(pproblem, state)
    symmetries = find_symmetries(pproblem, state, task)
    results = [outcome(search(task, SearchOptions(reward=500.0, threads=t), symmetries))
               for t in (1, 2, None)]
    assert results[0] == results[1] == results[2]
    assert results[0][0] == PlanStatus.SOLVED and results[0][4] > 10  # a real search


def test_threads_must_be_one_or_two():
    for bad in (0, 3, -1, 2.0, "2", True):  # e.g. from a JSON payload of the HTTP API
        with pytest.raises(PlanningError, match="threads must be 1 or 2"):
            SearchOptions(threads=bad).check()
    assert SearchOptions(threads=2).check().threads == 2
