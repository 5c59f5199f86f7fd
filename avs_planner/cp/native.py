"""Packing a `GroundTask` for the compiled search core `avs_planner.cp._native`.

The C core runs the same search as `avs_planner.cp.search` (same plan, same expanded and
generated counts). This module turns the task into flat arrays: the actions once per action
table (cached, so `GroundTask.with_init` replans reuse them), the initial state, goal,
symmetries and options on every call; a task's derived predicates' rules go with its
actions (the core closes each successor under them). `AVAILABLE` says whether the extension
was built.
"""

from __future__ import annotations

import math
import operator
import sys
import time
from array import array
from collections import OrderedDict
from itertools import chain

from avs_planner.cp.relaxed_merge import merge_task
from avs_planner.cp.symmetry import Symmetries
from avs_planner.cp.task import GroundTask, fact_ids
from avs_planner.errors import PlanningError

try:
    from avs_planner.cp import _native
except ImportError:  # not built (no compiler): the Python search is used
    _native = None

HEURISTIC_CODES = {"blind": 0, "hmax": 1, "hadd": 2, "ff": 3}
STATUS_NAMES = ("solved", "unsolvable", "no_plan_above_threshold", "timeout", "node_limit")
STOP_NAMES = (None, "timeout", "node_limit", "patience")  # _native.c STOP_*
_CACHE_SIZE = 8
if sys.byteorder != "little":  # the packed words are little-endian uint64
    _native = None
AVAILABLE = _native is not None
_packed: OrderedDict[int, tuple[tuple, tuple, object]] = OrderedDict()


def words(n_facts: int) -> int:
    """uint64 words per state bitset (one spare bit so n_facts = 0 still has a word)."""
    return n_facts // 64 + 1


def _bits(mask: int, n_bytes: int, n_facts: int, where) -> bytes:
    """Little-endian uint64 words of a bitset; `where` (or a callable giving it) names the
    owner in the error."""
    if mask < 0 or mask.bit_length() > n_facts:
        where = where() if callable(where) else where
        raise PlanningError(f"native search: {where} names a fact outside the task's "
                            f"{n_facts} facts")
    return mask.to_bytes(n_bytes, "little")


def pack_task(task: GroundTask):
    """The `_native.Task` for this task's actions (kept with a grounder's action table; for
    plain tuples, in a small LRU per action table and fact table)."""
    if _native is None:
        raise PlanningError("native search core is not built (pip install -e . builds it)")
    memo = getattr(task.actions, "memo", None)
    if memo is not None:  # an ActionTable: the packed task lives (and dies) with it
        hit = memo.get("native")
        if hit is None or hit[0] is not task.facts or hit[2] is not task.axioms:
            hit = memo["native"] = (task.facts, _pack(task), task.axioms)
        return hit[1]
    key = id(task.actions)
    hit = _packed.get(key)
    if (hit is not None and hit[0] is task.actions and hit[1] is task.facts
            and hit[3] is task.axioms):
        _packed.move_to_end(key)
        return hit[2]
    packed = _pack(task)
    _packed[key] = (task.actions, task.facts, packed, task.axioms)  # strong refs: ids stay
    while len(_packed) > _CACHE_SIZE:
        _packed.popitem(last=False)
    return packed


def _pack(task: GroundTask):
    base = task_arrays(task) if task.arrays is not None else task_args(task)
    return _native.Task(*base, *merge_args(merge_task(task)), *axiom_args(task))


def axiom_args(task: GroundTask) -> tuple:
    """The optional arguments of `_native.Task` for a task's derived predicates' rules: the
    packed rules and, per action, the facts it reads through them (n_actions * W words, so
    the core's commutation test sees them); none without rules."""
    import numpy as np

    axioms = task.axioms
    if axioms is None or not len(axioms):
        return ()
    n_facts, n_words = len(task.facts), words(len(task.facts))
    extra = np.zeros((len(task.actions), n_words), dtype="<u8")
    derived = np.zeros(n_facts + 1, dtype=bool)  # the spare last slot: -1 padding reads it
    derived[list(axioms.derived)] = True
    if task.arrays is not None and len(task.actions):  # only actions reading a derived fact
        reading = np.zeros(len(task.actions), dtype=bool)
        for m in (task.arrays.pre, task.arrays.pre_neg):
            m = np.asarray(m, dtype=np.int64).reshape(len(task.actions), -1)
            reading |= derived[m].any(axis=1)
        reading[list(task.arrays.clauses)] = True
        actions = task.steps(np.flatnonzero(reading).tolist())
    else:
        actions = list(task.actions)
    n_bytes = 8 * n_words
    for a in actions:
        more = axioms.expanded_reads(a.reads) & ~a.reads
        if more:
            extra[a.index] = np.frombuffer(_bits(more, n_bytes, n_facts, a.label), "<u8")
    return axioms.native_args().tobytes(), extra.tobytes()



def merge_args(merge) -> tuple:
    """The arguments of `_native.Task` for a `relaxed_merge.RelaxedMerge`."""
    import numpy as np

    def b(x) -> bytes:
        return np.ascontiguousarray(x, dtype="<i8").tobytes()

    return (merge.n_rfacts, merge.n_merged, b(merge.pre_off), b(merge.pre), b(merge.add_off),
            b(merge.add), b(merge.away), b(merge.weight_of), b(merge.link), b(merge.member_off),
            b(merge.members))


def _check_actions(task: GroundTask) -> tuple[bytes, bytes, bytes]:
    """Indices in order, finite costs, p in [0, 1]; returns cost, p and -log p as float64
    (computed with math.log per distinct p, as RelaxedTask.neglog; p = 0, never grounded,
    makes the action unusable)."""
    import numpy as np

    actions = task.actions
    # the grounder's arrays are index-aligned by construction; hand-built tuples are checked
    if task.arrays is None and not all(map(
            operator.eq, map(operator.attrgetter("index"), actions), range(len(actions)))):
        bad = next(a for i, a in enumerate(actions) if a.index != i)
        raise PlanningError(f"native search: action {bad.label} has index {bad.index}, "
                            f"not {actions.index(bad)}")
    if task.arrays is not None:
        cost = np.asarray(task.arrays.cost, dtype="<f8")
        probability = np.asarray(task.arrays.probability, dtype="<f8")
    else:
        cost = np.fromiter(map(operator.attrgetter("cost"), actions), "<f8", len(actions))
        probability = np.fromiter(map(operator.attrgetter("probability"), actions), "<f8",
                                  len(actions))
    if len(cost) != len(actions) or len(probability) != len(actions):
        raise PlanningError("native search: the task's arrays do not match its actions")
    if not (np.isfinite(cost).all() and ((probability >= 0) & (probability <= 1)).all()):
        raise PlanningError("native search: an action's cost is not finite or its "
                            "probability is not in [0, 1]")
    values, inverse = np.unique(probability, return_inverse=True)
    logs = np.array([-math.log(p) if p > 0 else math.inf for p in values.tolist()], "<f8")
    # arrays go to `_native.Task` as they are (it copies any C-contiguous buffer)
    return (np.ascontiguousarray(cost), np.ascontiguousarray(probability),
            logs[inverse.ravel()])


def _clauses(task: GroundTask, n_bytes: int, n_facts: int) -> tuple[bytes, bytes, bytes]:
    """CSR offsets per action and the packed (pos, neg) bitsets of the disjunctive clauses."""
    import numpy as np

    if task.arrays is not None:
        by_action = task.arrays.clauses
    else:
        by_action = {a.index: a.clauses for a in task.actions if a.clauses}
    n_actions = len(task.actions)
    offsets = np.zeros(n_actions + 1, dtype="<i8")
    pos_words, neg_words = [], []
    packed: dict[tuple, tuple[bytes, bytes]] = {}  # rows often share their clauses
    for i in sorted(by_action):
        if not 0 <= i < n_actions:
            raise PlanningError("native search: a clause names an action outside the task")
        clauses = by_action[i]
        offsets[i + 1] = len(clauses)
        words_of = packed.get(clauses)
        if words_of is None:
            def where(i=i) -> str:
                return task.actions[i].label
            words_of = packed[clauses] = (
                b"".join(_bits(pos, n_bytes, n_facts, where) for pos, _ in clauses),
                b"".join(_bits(neg, n_bytes, n_facts, where) for _, neg in clauses),
            )
        pos_words.append(words_of[0])
        neg_words.append(words_of[1])
    np.cumsum(offsets, out=offsets)
    return offsets.tobytes(), b"".join(pos_words), b"".join(neg_words)


def _csr(lists, n_facts: int, where: str) -> tuple[array, array]:
    offsets, values = array("q", [0]), array("q")
    for items in lists:
        values.extend(items)
        offsets.append(len(values))
    if values and (min(values) < 0 or max(values) >= n_facts):
        raise PlanningError(f"native search: {where} names a fact outside the task")
    return offsets, values


def packed_rows(offsets, values) -> bytes:
    """One action table's fact ids as `_native.Task` takes them: the CSR's n_actions + 1
    int64 offsets, then the ids (the core keeps each action's non-zero bitset words only)."""
    import numpy as np

    return (np.ascontiguousarray(offsets, dtype="<i8").tobytes()
            + np.ascontiguousarray(values, dtype="<i8").tobytes())


def _fact_ids(mask: int, n_facts: int, where) -> list[int]:  # noqa: ANN001 - a label thunk
    """The facts of a bitset, ascending; PlanningError if one lies outside the task."""
    if mask < 0 or mask >> n_facts:
        raise PlanningError(f"native search: {where()} names a fact outside the task")
    return fact_ids(mask)


def task_args(task: GroundTask) -> tuple:
    """The arguments of `_native.Task` from the `GroundAction`s (any task)."""
    n_facts, actions = len(task.facts), task.actions
    n_bytes = 8 * words(n_facts)
    rows = []
    for field in ("pre", "pre_neg", "add", "delete"):
        off, ids = _csr((_fact_ids(getattr(a, field), n_facts, lambda a=a: a.label)
                         for a in actions), n_facts, "an action")
        rows.append(packed_rows(off, ids))
    pre_off, pre_facts = _csr((a.pre_facts for a in actions), n_facts, "a precondition")
    add_off, add_facts = _csr((a.add_facts for a in actions), n_facts, "an effect")
    return (n_facts, len(actions), *rows, *_check_actions(task),
            pre_off, pre_facts, add_off, add_facts, *_clauses(task, n_bytes, n_facts))


def task_arrays(task: GroundTask) -> tuple:
    """The same arguments from `task.arrays` (the grounder's fact-id matrices: sorted, unique,
    -1 padded; `pre` rows are the `pre_facts`), vectorised: ~10x faster on 6,000 actions."""
    import numpy as np

    arrays, n_facts, n_actions = task.arrays, len(task.facts), len(task.actions)
    n_words = words(n_facts)

    def matrix(m) -> np.ndarray:
        m = np.asarray(m, dtype=np.int64)
        if not m.size:
            m = np.zeros((n_actions, 0), np.int64)
        if m.ndim != 2 or m.shape[0] != n_actions:
            raise PlanningError("native search: the task's arrays do not match its actions")
        if m.size and (m.max() >= n_facts or m.min() < -1):
            raise PlanningError("native search: the task's arrays name a fact outside it")
        return m

    def csr(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        valid = m >= 0
        offsets = np.zeros(n_actions + 1, dtype="<i8")
        np.cumsum(valid.sum(axis=1), out=offsets[1:])
        return offsets, np.ascontiguousarray(m[valid], dtype="<i8")

    pre, neg, add, delete = (matrix(m) for m in (arrays.pre, arrays.pre_neg, arrays.add,
                                                 arrays.delete))
    pre_csr, add_csr = csr(pre), csr(add)
    return (n_facts, n_actions, packed_rows(*pre_csr), packed_rows(*csr(neg)),
            packed_rows(*add_csr), packed_rows(*csr(delete)),
            *_check_actions(task), *pre_csr, *add_csr,
            *_clauses(task, 8 * n_words, n_facts))


def pack_symmetries(symmetries: Symmetries, n_actions: int, n_facts: int) -> tuple:
    """(act_off, pair_ids, pair_off, fact pairs) for `Symmetries.prunes`; empty if none."""
    import numpy as np

    checks = symmetries.checks
    if not checks:
        return b"", b"", b"", b""
    pair_index, pair_off, fg = _pack_fact_pairs(symmetries.fact_pairs, n_facts)
    if symmetries.grouped is not None:
        return (*_pack_grouped(symmetries.grouped, pair_index, n_actions), pair_off, fg)
    actions = np.fromiter(checks.keys(), np.int64, len(checks))
    if actions.min() < 0 or actions.max() >= n_actions:
        raise PlanningError("native search: symmetries name actions outside the task")
    if len(actions) > 1 and not (np.diff(actions) > 0).all():
        checks = {a: checks[a] for a in sorted(checks)}
        actions.sort()
    try:
        ids = np.fromiter(map(pair_index.__getitem__, chain.from_iterable(checks.values())),
                          np.int64)
    except KeyError:
        raise PlanningError("native search: a symmetry check names an unknown pair") from None
    act_off = np.zeros(n_actions + 1, dtype="<i8")
    act_off[actions + 1] = np.fromiter(map(len, checks.values()), np.int64, len(checks))
    np.cumsum(act_off, out=act_off)
    return act_off.tobytes(), ids.astype("<i8").tobytes(), pair_off, fg


def _packed_symmetries(task: GroundTask, symmetries: Symmetries) -> tuple:
    """`pack_symmetries`, kept with a grounder's action table for the last symmetries
    packed (the symmetry finder hands a replan with the same groups the same object)."""
    memo = getattr(task.actions, "memo", None)
    hit = memo.get("native_symmetries") if memo is not None else None
    if hit is not None and hit[0] is symmetries and hit[1] is task.facts:
        return hit[2]
    packed = pack_symmetries(symmetries, len(task.actions), len(task.facts))
    if memo is not None:
        memo["native_symmetries"] = (symmetries, task.facts, packed)
    return packed


def _pack_grouped(grouped: tuple, pair_index: dict, n_actions: int) -> tuple[bytes, bytes]:
    """(act_off, pair ids) from `Symmetries.grouped`: the pair ids are looked up once per
    distinct pair list and gathered per action with array arithmetic."""
    import numpy as np

    actions, which, pair_lists = grouped
    actions = np.asarray(actions, dtype=np.int64)
    if len(actions) and (actions[0] < 0 or actions[-1] >= n_actions
                         or not (np.diff(actions) > 0).all()):
        raise PlanningError("native search: symmetries name actions outside the task")
    try:
        lists = [np.fromiter(map(pair_index.__getitem__, pairs), np.int64, len(pairs))
                 for pairs in pair_lists]
    except KeyError:
        raise PlanningError("native search: a symmetry check names an unknown pair") from None
    lengths = np.array([len(x) for x in lists], dtype=np.int64)
    flat = np.concatenate(lists) if lists else np.zeros(0, dtype=np.int64)
    starts = np.cumsum(lengths) - lengths
    counts = lengths[which]
    act_off = np.zeros(n_actions + 1, dtype="<i8")
    act_off[actions + 1] = counts
    np.cumsum(act_off, out=act_off)
    ends = np.cumsum(counts)
    total = int(ends[-1]) if len(ends) else 0
    gather = np.repeat(starts[which] - (ends - counts), counts) + np.arange(total)
    return act_off.tobytes(), flat[gather].astype("<i8").tobytes()


_fact_pairs_packed: OrderedDict[int, tuple] = OrderedDict()


def _pack_fact_pairs(fact_pairs, n_facts: int) -> tuple[dict, bytes, bytes]:
    """Pair ids and the flattened (f, g) lists; cached per fact_pairs mapping (the symmetry
    finder keeps one per fact table)."""
    key = (id(fact_pairs), n_facts)
    hit = _fact_pairs_packed.get(key)
    if hit is not None and hit[0] is fact_pairs:
        _fact_pairs_packed.move_to_end(key)
        return hit[1]
    pair_index = {pair: i for i, pair in enumerate(fact_pairs)}
    pair_off, fg = array("q", [0]), array("q")
    for pairs in fact_pairs.values():
        for f, g in pairs:
            if not (0 <= f < n_facts and -1 <= g < n_facts):
                raise PlanningError("native search: symmetries name facts outside the task")
            fg.append(f)
            fg.append(g)
        pair_off.append(len(fg) // 2)
    packed = (pair_index, pair_off.tobytes(), fg.tobytes())
    _fact_pairs_packed[key] = (fact_pairs, packed)  # strong ref: the id stays unique
    while len(_fact_pairs_packed) > _CACHE_SIZE:
        _fact_pairs_packed.popitem(last=False)
    return packed


def run(
    task: GroundTask,
    heuristic: str,
    reward: float,
    weight: float,
    min_success: float,
    timeout_s: float | None,
    node_limit: int | None,
    patience: float,
    lazy: int,
    preferred: bool,
    symmetries: Symmetries,
    start: float,
    threads: int | None = None,
    goal_count: bool = False,
    commute: bool = True,
) -> tuple[str, tuple[int, ...], int, int, str | None]:
    """Run the C search: (status name, action indices of the plan, expanded, generated, why
    the best plan so far was returned: one of STOP_NAMES). `threads`: 1 or 2 evaluating
    threads, None for the core's choice (two for large tasks on a multi-CPU machine).
    `lazy`: one of search_modes.py's EAGER, DEFERRED, DEFERRED_UNHELPFUL. `preferred`,
    `goal_count` and not `commute` go to the core as the bits 1, 2 and 4 of its queue
    flags (the core's QF_*)."""
    packed = pack_task(task)
    n_facts = len(task.facts)
    n_bytes = 8 * words(n_facts)
    sym = _packed_symmetries(task, symmetries)
    remaining = -1.0
    if timeout_s is not None:  # the clock started with the search call, as in Python
        remaining = max(0.0, timeout_s - (time.perf_counter() - start))
    status, path, expanded, generated, stopped = _native.search(
        packed,
        _bits(task.init, n_bytes, n_facts, "the initial state"),
        _bits(task.goal, n_bytes, n_facts, "the goal"),
        _bits(task.goal_neg, n_bytes, n_facts, "the goal"),
        HEURISTIC_CODES[heuristic], float(reward), float(weight), float(min_success),
        remaining, _c_limit(node_limit), _c_limit(patience), int(lazy),
        int(preferred) | (2 if goal_count else 0) | (0 if commute else 4), *sym,
        0 if threads is None else threads,
    )
    return STATUS_NAMES[status], path, expanded, generated, STOP_NAMES[stopped]


def _c_limit(limit: float | None) -> int:
    """An expansion limit for the C core: -1 for none (None, inf, or more expansions than an
    int64 counter reaches, which C could not even take as an argument)."""
    if limit is None or limit >= 2**62:
        return -1
    return int(limit)


def closures(task: GroundTask, states: list[int]) -> list[int]:
    """The C core's closure of each state under the task's rules, as the search closes its
    successors (`ground_axioms.GroundAxioms.close` computes the same)."""
    packed = pack_task(task)
    n_facts = len(task.facts)
    n_bytes = 8 * words(n_facts)
    blob = _native.close(packed, b"".join(_bits(s, n_bytes, n_facts, "a state")
                                          for s in states))
    return [int.from_bytes(blob[i:i + n_bytes], "little")
            for i in range(0, len(blob), n_bytes)]


def estimates(
    task: GroundTask, heuristic: str, reward: float, states: list[int]
) -> list[tuple[float, float, tuple[int, ...]]]:
    """The C heuristic alone: (hc, hl, helpful actions) per state, as heuristics.py gives."""
    packed = pack_task(task)
    n_facts = len(task.facts)
    n_bytes = 8 * words(n_facts)
    blob = b"".join(_bits(s, n_bytes, n_facts, "a state") for s in states)
    return _native.estimates(packed, _bits(task.goal, n_bytes, n_facts, "the goal"),
                             HEURISTIC_CODES[heuristic], float(reward), blob)
