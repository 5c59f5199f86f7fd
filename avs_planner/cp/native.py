"""Packing a `GroundTask` for the compiled search core `avs_planner.cp._native`.

The C core runs the same search as `avs_planner.cp.search` (same plan, same expanded and
generated counts). This module turns the task into flat arrays: the actions once per action
table (cached, so `GroundTask.with_init` replans reuse them), the initial state, goal,
symmetries and options on every call. `AVAILABLE` says whether the extension was built.
"""

from __future__ import annotations

import math
import time
from array import array
from collections import OrderedDict

from avs_planner.cp.symmetry import Symmetries
from avs_planner.cp.task import GroundTask
from avs_planner.errors import PlanningError

try:
    from avs_planner.cp import _native
except ImportError:  # not built (no compiler): the Python search is used
    _native = None

AVAILABLE = _native is not None
HEURISTIC_CODES = {"blind": 0, "hmax": 1, "hadd": 2, "ff": 3}
STATUS_NAMES = ("solved", "unsolvable", "no_plan_above_threshold", "timeout", "node_limit")
_CACHE_SIZE = 8
_packed: OrderedDict[int, tuple[tuple, tuple, object]] = OrderedDict()


def words(n_facts: int) -> int:
    """uint64 words per state bitset (one spare bit so n_facts = 0 still has a word)."""
    return n_facts // 64 + 1


def _bits(mask: int, n_bytes: int, n_facts: int, where: str) -> bytes:
    if mask < 0 or mask.bit_length() > n_facts:
        raise PlanningError(f"native search: {where} names a fact outside the task's "
                            f"{n_facts} facts")
    return mask.to_bytes(n_bytes, "little")


def _csr(lists, n_facts: int, where: str) -> tuple[array, array]:
    offsets, values = array("q", [0]), array("q")
    for items in lists:
        values.extend(items)
        offsets.append(len(values))
    if values and (min(values) < 0 or max(values) >= n_facts):
        raise PlanningError(f"native search: {where} names a fact outside the task")
    return offsets, values


def pack_task(task: GroundTask):
    """The `_native.Task` for this task's actions (cached per action table and fact table)."""
    if _native is None:
        raise PlanningError("native search core is not built (pip install -e . builds it)")
    key = id(task.actions)
    hit = _packed.get(key)
    if hit is not None and hit[0] is task.actions and hit[1] is task.facts:
        _packed.move_to_end(key)
        return hit[2]
    packed = _pack(task)
    _packed[key] = (task.actions, task.facts, packed)  # strong refs: ids stay unique
    while len(_packed) > _CACHE_SIZE:
        _packed.popitem(last=False)
    return packed


def _pack(task: GroundTask):
    n_facts, actions = len(task.facts), task.actions
    n_bytes = 8 * words(n_facts)
    masks: list[list[bytes]] = [[], [], [], []]
    clause_off, clause_pos, clause_neg = array("q", [0]), [], []
    for i, a in enumerate(actions):
        if a.index != i:
            raise PlanningError(f"native search: action {a.label} has index {a.index}, not {i}")
        if not (math.isfinite(a.cost) and 0.0 <= a.probability <= 1.0):
            raise PlanningError(f"native search: action {a.label} has cost {a.cost} and "
                                f"probability {a.probability}")
        for out, mask in zip(masks, (a.pre, a.pre_neg, a.add, a.delete), strict=True):
            out.append(_bits(mask, n_bytes, n_facts, a.label))
        for pos, neg in a.clauses:
            clause_pos.append(_bits(pos, n_bytes, n_facts, a.label))
            clause_neg.append(_bits(neg, n_bytes, n_facts, a.label))
        clause_off.append(len(clause_pos))
    pre_off, pre_facts = _csr((a.pre_facts for a in actions), n_facts, "a precondition")
    add_off, add_facts = _csr((a.add_facts for a in actions), n_facts, "an effect")
    return _native.Task(
        n_facts, len(actions), *(b"".join(m) for m in masks),
        array("d", [float(a.cost) for a in actions]),
        array("d", [float(a.probability) for a in actions]),
        # as RelaxedTask.neglog; p = 0 (never grounded) makes the action unusable
        array("d", [-math.log(a.probability) if a.probability > 0 else math.inf
                    for a in actions]),
        pre_off, pre_facts, add_off, add_facts,
        clause_off, b"".join(clause_pos), b"".join(clause_neg),
    )


def pack_symmetries(symmetries: Symmetries, n_actions: int, n_facts: int) -> tuple:
    """(act_off, pair_ids, pair_off, fact pairs) for `Symmetries.prunes`; empty if none."""
    if not symmetries.checks:
        return b"", b"", b"", b""
    pair_index = {pair: i for i, pair in enumerate(symmetries.fact_pairs)}
    act_off, pair_ids = array("q", [0]), array("q")
    for a in range(n_actions):
        for pair in symmetries.checks.get(a, ()):
            pair_ids.append(pair_index[pair])
        act_off.append(len(pair_ids))
    if len(act_off) != n_actions + 1 or any(not 0 <= a < n_actions for a in symmetries.checks):
        raise PlanningError("native search: symmetries name actions outside the task")
    pair_off, fg = array("q", [0]), array("q")
    for pairs in symmetries.fact_pairs.values():
        for f, g in pairs:
            fg.append(f)
            fg.append(g)
        pair_off.append(len(fg) // 2)
    return act_off, pair_ids, pair_off, fg


def run(
    task: GroundTask,
    heuristic: str,
    reward: float,
    weight: float,
    min_success: float,
    timeout_s: float | None,
    node_limit: int | None,
    lazy: bool,
    preferred: bool,
    symmetries: Symmetries,
    start: float,
) -> tuple[str, tuple[int, ...], int, int]:
    """Run the C search: (status name, action indices of the plan, expanded, generated)."""
    packed = pack_task(task)
    n_facts = len(task.facts)
    n_bytes = 8 * words(n_facts)
    sym = pack_symmetries(symmetries, len(task.actions), n_facts)
    remaining = -1.0
    if timeout_s is not None:  # the clock started with the search call, as in Python
        remaining = max(0.0, timeout_s - (time.perf_counter() - start))
    status, path, expanded, generated = _native.search(
        packed,
        _bits(task.init, n_bytes, n_facts, "the initial state"),
        _bits(task.goal, n_bytes, n_facts, "the goal"),
        _bits(task.goal_neg, n_bytes, n_facts, "the goal"),
        HEURISTIC_CODES[heuristic], float(reward), float(weight), float(min_success),
        remaining, -1 if node_limit is None else int(node_limit), lazy, preferred, *sym,
    )
    return STATUS_NAMES[status], path, expanded, generated


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
