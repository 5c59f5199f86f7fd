"""Merging actions that differ in one argument, for the relaxed heuristics (h^max, h_add, FF).

Many ground actions differ only in an argument that picks one of several alternatives in the
precondition and leaves no other trace: SEARCHFOROBJECT-ON for one label, support and object
exists once per place of the room (`(at ?p)`), ASSUME-OBJ-EXISTS-ON once per room the support
could be in. In a delete relaxation such a group, with the same add effects, cost and
probability, acts as one action with a disjunctive precondition: min_i (C + R_i) = C + min_i
R_i for sums and maxima alike (C: what all members need, R_i: the rest of member i's). So the
relaxed task replaces the group by

- an auxiliary fact X, "some R_i holds", reached by one auxiliary action per remainder R_i
  (weight 0, counted in no estimate); groups with the same remainders share X (every search
  in one room shares "the robot is at a place of the room");
- a merged action M with precondition C + X and the members' add effects and weights.

h^max and h_add values are unchanged. FF's relaxed plan holds M where it held a member, with
the same cost, -log p and +1, and its helpful action is the member whose remainder reached X;
only ties between equally cheap alternatives may resolve to another member. On the 20-place
AVS problems this shrinks the relaxed task from ~4,400 actions and ~20,000 precondition
entries to ~1,400 and ~4,000. The search still applies the real actions; only the heuristics
(heuristics.py and the C core, from the same `RelaxedMerge`) use the merged ones.

The merge is built once per action table (kept in its `memo`, so a replan that reuses the
table reuses it), in C when the grounding extension is built (`_fixpoint.relaxed_merge`,
~1.5 ms on p20); the numpy functions below are the fallback and the tests' reference (~9 ms).

Relaxed action ids: the task's actions 0..A-1 (the merged-away ones take no part), then the
merged actions, then the auxiliary ones (the derived predicates' rules last, if the task has
any); auxiliary facts are numbered after the task's facts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

try:
    from avs_planner.cp import _fixpoint
except ImportError:  # not built: the numpy path
    _fixpoint = None

ENABLED = True  # False: the relaxed task is the task itself (for A/B measurements)
COMPILED = True  # False: the numpy path even when the compiled one is built (tests compare)
_HASH = np.random.default_rng(20261122).integers(1, 2**63, size=256, dtype=np.uint64) | 1


@dataclass(frozen=True)
class RelaxedMerge:
    """The task's actions minus `away`, plus E extra relaxed actions with ids
    n_actions..n_actions+E-1: the merged ones, then the auxiliary ones. Arrays (int64) per
    extra action: preconditions and add effects (CSR), the task action whose cost and
    probability it carries (`weight_of`, -1: weight 0) and `link`."""

    n_facts: int  # the task's facts; auxiliary facts are n_facts .. n_rfacts - 1
    n_rfacts: int
    n_actions: int  # the task's actions
    n_merged: int
    away: np.ndarray  # bool per task action: merged, so left out of the relaxation
    pre_off: np.ndarray
    pre: np.ndarray
    add_off: np.ndarray
    add: np.ndarray
    weight_of: np.ndarray
    link: np.ndarray
    """Merged action: its auxiliary fact X; auxiliary action: its position among X's
    alternatives."""
    member_off: np.ndarray
    members: np.ndarray
    """Per merged action (CSR): the task action behind each of its X's alternatives."""

    @property
    def n_extra(self) -> int:
        return len(self.weight_of)

    def member(self, merged: int, support: Sequence[int]) -> int:
        """The task action merged action `merged` (a relaxed id) stands for, given the relaxed
        supporters (the auxiliary action that reached its X)."""
        m = merged - self.n_actions
        aux = support[int(self.link[m])] - self.n_actions
        return int(self.members[self.member_off[m] + self.link[aux]])

    def extra_lists(self) -> tuple[list[tuple[int, ...]], list[tuple[int, ...]]]:
        """Preconditions and add effects of the extra actions as tuples."""
        def rows(off, values):
            values = values.tolist()
            return [tuple(values[a:b]) for a, b in zip(off[:-1].tolist(), off[1:].tolist(),
                                                        strict=True)]
        return rows(self.pre_off, self.pre), rows(self.add_off, self.add)


def merge_task(task) -> RelaxedMerge:
    """The `RelaxedMerge` of a `GroundTask`, kept with a grounder's action table (its
    `memo`) so the Python heuristics and the native packer share one; a task's derived
    predicates' rules are appended as auxiliary actions (`with_rules`)."""
    memo = getattr(task.actions, "memo", None)
    axioms = getattr(task, "axioms", None)
    if memo is not None:
        hit = memo.get("relaxed_merge")
        if hit is not None and hit[0] is task.facts and hit[2] is axioms:
            return hit[1]
    merge = _merge_task(task)
    if axioms is not None:
        merge = with_rules(merge, *axioms.relaxed())
    if memo is not None:
        memo["relaxed_merge"] = (task.facts, merge, axioms)
    return merge


def with_rules(merge: RelaxedMerge, pre: list[tuple[int, ...]], add: list[tuple[int, ...]]
               ) -> RelaxedMerge:
    """The merge with one more auxiliary action per rule (weight 0, counted in no estimate,
    as the merge's own auxiliary actions): a derived fact is reached at the cost of the
    rule's preconditions (`ground_axioms.py` says which literals those are)."""
    def extend(off: np.ndarray, values: np.ndarray, rows: list[tuple[int, ...]]
               ) -> tuple[np.ndarray, np.ndarray]:
        more = np.cumsum([len(r) for r in rows], dtype=np.int64) + off[-1]
        flat = np.fromiter((f for r in rows for f in r), dtype=np.int64)
        return np.concatenate([off, more]), np.concatenate([values, flat])

    pre_off, pre_v = extend(merge.pre_off, merge.pre, pre)
    add_off, add_v = extend(merge.add_off, merge.add, add)
    extra = len(pre)
    return RelaxedMerge(
        merge.n_facts, merge.n_rfacts, merge.n_actions, merge.n_merged, merge.away,
        pre_off, pre_v, add_off, add_v,
        np.concatenate([merge.weight_of, np.full(extra, -1, dtype=np.int64)]),
        np.concatenate([merge.link, np.zeros(extra, dtype=np.int64)]),
        merge.member_off, merge.members)


def _merge_task(task) -> RelaxedMerge:
    n_facts, arrays, n_actions = len(task.facts), task.arrays, len(task.actions)
    if n_actions < 2 or not ENABLED:
        return build_merge(n_facts, np.zeros((n_actions, 0), dtype=np.int64),
                           np.zeros((n_actions, 0), dtype=np.int64),
                           np.full(n_actions, -1, dtype=np.int64))
    if arrays is not None and arrays.arg_ids is not None:
        pre = np.asarray(arrays.pre, dtype=np.int64).reshape(n_actions, -1)
        add = np.asarray(arrays.add, dtype=np.int64).reshape(n_actions, -1)
        args = np.asarray(arrays.arg_ids, dtype=np.int64).reshape(n_actions, -1)
        cost = np.asarray(arrays.cost, dtype=np.float64)
        probability = np.asarray(arrays.probability, dtype=np.float64)
        clauses = arrays.clauses
    else:
        actions = task.actions
        pre, add = (_padded([sorted(getattr(a, f)) for a in actions]) for f in
                    ("pre_facts", "add_facts"))
        ids: dict[str, int] = {}
        args = _padded([[ids.setdefault(x, len(ids)) for x in a.args] for a in actions])
        cost = np.array([a.cost for a in actions], dtype=np.float64)
        probability = np.array([a.probability for a in actions], dtype=np.float64)
        clauses = {a.index: a.clauses for a in actions if a.clauses}
    eligible = (add >= 0).any(axis=1) if add.size else np.zeros(n_actions, dtype=bool)
    if clauses:
        eligible[list(clauses)] = False
    if _fixpoint is not None and COMPILED:
        return compiled_merge(n_facts, args, pre, add, cost, probability, eligible)
    groups = one_argument_groups(args, add, cost, probability, eligible)
    return build_merge(n_facts, pre, add, groups)


def compiled_merge(n_facts: int, args: np.ndarray, pre: np.ndarray, add: np.ndarray,
                   cost: np.ndarray, probability: np.ndarray,
                   eligible: np.ndarray) -> RelaxedMerge:
    """`one_argument_groups` + `build_merge` in C (`_fixpoint.relaxed_merge`): the same
    RelaxedMerge, ~20x faster (the numpy path cost 3-10 ms per call on 20-place problems)."""
    def c64(m: np.ndarray, width: int) -> np.ndarray:
        return np.ascontiguousarray(m, dtype=np.int64).reshape(len(args), width)

    n, arity = args.shape
    wp = pre.shape[1] if pre.ndim == 2 else 0
    wa = add.shape[1] if add.ndim == 2 else 0
    out = _fixpoint.relaxed_merge(
        n, arity, wp, wa, n_facts, c64(args, arity), c64(pre, wp), c64(add, wa),
        np.ascontiguousarray(cost, dtype=np.float64).view(np.int64),
        np.ascontiguousarray(probability, dtype=np.float64).view(np.int64),
        np.ascontiguousarray(eligible, dtype=np.uint8), _HASH)
    n_rfacts, n_merged, away, *arrays = out
    pre_off, pre_v, add_off, add_v, weight_of, link, member_off, members = (
        np.frombuffer(a, dtype=np.int64) for a in arrays)
    return RelaxedMerge(n_facts, n_rfacts, n, n_merged,
                        np.frombuffer(away, dtype=np.uint8).astype(bool), pre_off, pre_v,
                        add_off, add_v, weight_of, link, member_off, members)


def _padded(rows: list[list[int]]) -> np.ndarray:
    out = np.full((len(rows), max(map(len, rows), default=0)), -1, dtype=np.int64)
    for i, row in enumerate(rows):
        out[i, :len(row)] = row
    return out


def one_argument_groups(args: np.ndarray, add: np.ndarray, cost: np.ndarray,
                        probability: np.ndarray, eligible: np.ndarray) -> np.ndarray:
    """Group id per action (-1: none) over eligible actions with the same add effects, cost
    and probability whose arguments differ in one position only; groups have two or more
    members and are numbered by first member. Positions are tried by how many actions they
    would merge, most first; an action joins one group. (Array operations only: this runs
    on every cold planning call.)"""
    n, arity = args.shape
    gid = np.full(n, -1, dtype=np.int64)
    if n < 2 or not arity:
        return gid
    key = np.hstack([args, add, cost.view(np.int64)[:, None],
                     probability.view(np.int64)[:, None]]).astype(np.uint64)
    masked = _row_hashes(key, skip=range(arity))
    free = eligible.copy()

    def by_key(k: int) -> tuple[np.ndarray, np.ndarray]:
        idx = np.flatnonzero(free & (args[:, k] >= 0))
        h = masked[k][idx]
        order = np.argsort(h)
        return idx[order], h[order]

    gains = [int((h[1:] == h[:-1]).sum()) for h in (by_key(k)[1] for k in range(arity))]
    n_groups = 0
    for k in sorted(range(arity), key=lambda k: (-gains[k], k)):
        if not gains[k]:
            break
        order, h = by_key(k)
        rows = key[order]
        rows[:, k] = 0
        same = (h[1:] == h[:-1]) & (rows[1:] == rows[:-1]).all(axis=1)
        run = np.concatenate([[0], np.cumsum(~same)])  # run id per sorted action
        grouped = np.bincount(run)[run] > 1
        if not grouped.any():
            continue
        r = run[grouped]
        gid[order[grouped]] = n_groups + np.concatenate([[0], np.cumsum(r[1:] != r[:-1])])
        n_groups = int(gid.max()) + 1
        free[order[grouped]] = False
    if n_groups:  # renumber by first member
        m = np.flatnonzero(gid >= 0)
        first = np.full(n_groups, n, dtype=np.int64)
        first[gid[m][::-1]] = m[::-1]
        rank = np.empty(n_groups, dtype=np.int64)
        rank[np.argsort(first)] = np.arange(n_groups)
        gid[m] = rank[gid[m]]
    return gid


def _row_hashes(m: np.ndarray, skip=()) -> list[np.ndarray] | np.ndarray:
    """A 64-bit hash of each row of the uint64 matrix `m`; with `skip`, one array per listed
    column: the hash without that column. Equal rows hash equal; callers compare rows to be
    exact."""
    weights = _HASH[np.arange(m.shape[1]) % len(_HASH)]
    with np.errstate(over="ignore"):
        full = (m * weights).sum(axis=1, dtype=np.uint64)
        if skip == ():
            return full
        return [full - m[:, k] * weights[k] for k in skip]


def _runs(sorted_keys: np.ndarray) -> np.ndarray:
    """Run id of each element of a sorted array (0, 0, 1, 2, 2, ...)."""
    return np.concatenate([[0], np.cumsum(sorted_keys[1:] != sorted_keys[:-1])])


def build_merge(n_facts: int, pre: np.ndarray, add: np.ndarray,
                gid: np.ndarray) -> RelaxedMerge:
    """Merge each group whose members all need something beyond their common preconditions
    (a member needing nothing more would make X free). `pre`, `add`: per task action its
    sorted fact ids, -1 padded; `gid` from `one_argument_groups`. Array operations only."""
    n_actions = len(pre)
    away = np.zeros(n_actions, dtype=bool)
    none = np.zeros(0, dtype=np.int64)
    zero = np.zeros(1, dtype=np.int64)
    empty = RelaxedMerge(n_facts, n_facts, n_actions, 0, away, zero, none, zero, none,
                         none, none, zero, none)
    members = np.flatnonzero(gid >= 0)
    if not len(members) or not pre.shape[1]:
        return empty
    order = np.argsort(gid[members] * n_actions + members)
    members = members[order]
    g = gid[members]
    n_groups = int(g[-1]) + 1
    sizes = np.bincount(g, minlength=n_groups)
    big = 2**62  # padding: above every fact id, auxiliary ones included
    rows = pre[members]
    valid = rows >= 0
    # how many members of its group have each precondition: all of them = common
    keys = (g[:, None] * (n_facts + 1) + np.where(valid, rows, n_facts))[valid]
    by = np.argsort(keys)
    run = _runs(keys[by])
    count = np.empty(len(keys), dtype=np.int64)
    count[by] = np.bincount(run)[run]
    counts = np.zeros(rows.shape, dtype=np.int64)
    counts[valid] = count
    rest = valid & (counts < sizes[g][:, None])
    ok = np.ones(n_groups, dtype=bool)
    ok[g[~rest.any(axis=1)]] = False
    keep = ok[g]
    if not keep.any():
        return empty
    members, g, rows, valid, rest = members[keep], g[keep], rows[keep], valid[keep], rest[keep]
    away[members] = True
    g = _runs(g)  # dense ids over the merged groups, same order
    n_m = int(g[-1]) + 1
    start = np.searchsorted(g, np.arange(n_m))
    common = np.sort(np.where(valid & ~rest, rows, big)[start], axis=1)
    alt = np.sort(np.where(rest, rows, big), axis=1)  # each member's remainder, big-padded
    # members by (group, remainder by content, id): groups with the same remainders list
    # them in the same order; a repeated remainder keeps the lowest id
    ha = _row_hashes(alt.astype(np.uint64))
    g_bits, m_bits = max(1, int(n_m).bit_length()), max(1, int(n_actions).bit_length())
    h_bits = 64 - g_bits - m_bits
    if h_bits >= 16:
        composite = ((g.astype(np.uint64) << np.uint64(64 - g_bits))
                     | ((ha >> np.uint64(64 - h_bits)) << np.uint64(m_bits))
                     | members.astype(np.uint64))
        order = np.argsort(composite)
    else:
        order = np.lexsort((members, ha, g))
    members, g, alt = members[order], g[order], alt[order]
    dup = np.zeros(len(g), dtype=bool)
    dup[1:] = (g[1:] == g[:-1]) & (alt[1:] == alt[:-1]).all(axis=1)
    members, g, alt = members[~dup], g[~dup], alt[~dup]
    sizes = np.bincount(g, minlength=n_m)
    start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    pos = np.arange(len(g)) - start[g]
    width = alt.shape[1]
    table = np.full((n_m, int(sizes.max()) * width), big, dtype=np.int64)
    table[g[:, None], pos[:, None] * width + np.arange(width)] = alt
    # X per distinct table row, numbered by the first group that has it
    ht = _row_hashes(table.astype(np.uint64))
    by = np.argsort(ht, kind="stable")  # groups ascending within equal hashes
    st = table[by]
    new = np.ones(n_m, dtype=bool)
    new[1:] = (ht[by][1:] != ht[by][:-1]) | (st[1:] != st[:-1]).any(axis=1)
    run = np.cumsum(new) - 1
    rep_group = by[new]  # per run: its first (lowest) group
    x_rank = np.empty(len(rep_group), dtype=np.int64)
    x_rank[np.argsort(rep_group)] = np.arange(len(rep_group))
    x_of = np.empty(n_m, dtype=np.int64)
    x_of[by] = x_rank[run]
    x_groups = np.sort(rep_group)  # the group whose alternatives stand for X, by X id
    n_x = len(x_groups)
    # extra actions: merged (one per group), then auxiliary (one per alternative of each X)
    m_pre = np.hstack([common, (n_facts + x_of)[:, None]])
    m_add = add[members[start]]
    aux_sizes = sizes[x_groups]
    aux_pos = np.arange(int(aux_sizes.sum())) - np.repeat(np.cumsum(aux_sizes) - aux_sizes,
                                                          aux_sizes)
    aux_pre = alt[np.repeat(start[x_groups], aux_sizes) + aux_pos]
    aux_add = np.repeat(n_facts + np.arange(n_x), aux_sizes)[:, None]
    pre_off, pre_v = _csr([m_pre, aux_pre], big)
    add_off, add_v = _csr([np.where(m_add < 0, big, m_add), aux_add], big)
    weight_of = np.concatenate([members[start], np.full(len(aux_pos), -1, dtype=np.int64)])
    link = np.concatenate([n_facts + x_of, aux_pos]).astype(np.int64)
    member_off = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    return RelaxedMerge(n_facts, n_facts + n_x, n_actions, n_m, away, pre_off, pre_v,
                        add_off, add_v, weight_of, link, member_off, members.astype(np.int64))


def _csr(parts: list[np.ndarray], big: int) -> tuple[np.ndarray, np.ndarray]:
    """The rows of the matrices in `parts`, one after another, without their `big` padding,
    as offsets and values."""
    lengths, values = [], []
    for m in parts:
        valid = m != big
        lengths.append(valid.sum(axis=1))
        values.append(m[valid])
    off = np.concatenate([[0], np.cumsum(np.concatenate(lengths))]).astype(np.int64)
    return off, np.concatenate(values).astype(np.int64)
