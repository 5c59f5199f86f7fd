"""Arrays derived from a grounding structure, and the per-call fixpoints that run on them.

`derived(st)` is kept with its `GroundStructure` (`GroundStructure.memo`). It fills in, as calls
need rows, each row's facts sorted and unique, as fact-id matrices (no bitset words: the native
core keeps an action's non-zero words only, built from these ids); it also holds the rows'
clause facts as CSR. A planning call takes its kept rows from these (`task_rows`) instead of
sorting them again. `reachable` and `relevant` are the grounder's two fixpoints, in C
(`avs_planner.cp._fixpoint`) when built, else in numpy (the same result; tests compare them).
"""

from __future__ import annotations

import numpy as np

from avs_planner.cp.structure import GroundStructure, bitset, fact_matrix

try:  # the compiled fixpoints; the numpy versions below compute the same when not built
    from avs_planner.cp import _fixpoint
except ImportError:
    _fixpoint = None
_BIG = np.iinfo(np.int64).max


def ids_of(mask: int) -> np.ndarray:
    """The fact ids of a Python int bitset, ascending."""
    if not mask:
        return np.zeros(0, dtype=np.int64)
    data = np.frombuffer(mask.to_bytes((mask.bit_length() + 7) // 8, "little"), np.uint8)
    return np.flatnonzero(np.unpackbits(data, bitorder="little")).astype(np.int64)


class Derived:
    """Per structure row, filled on first use by `rows` (the numpy path of `task_rows`):
    sorted unique fact ids (-1 padded at the end) of pre, pre_neg, add, delete. Computed
    at once: the rows' clause facts as (interleaved offsets, positives, negatives) plus the
    row of each clause fact and each clause row's clauses as bitsets, and (when the compiled
    fixpoints are built) the rows-by-fact indexes they take."""

    def __init__(self, st: GroundStructure):
        self._st = st
        self._cache: tuple | None = None  # (done flags, matrices), made by `rows`
        self.clauses = _clause_csr(st)
        clause_rows = sorted(st.clauses)
        self.clause_rows = np.array(clause_rows, dtype=np.int64)
        bits_of: dict[tuple, tuple[tuple[int, int], ...]] = {}  # rows share clause lists
        self.clause_bits = {}
        for row in clause_rows:
            clauses = st.clauses[row]
            bits = bits_of.get(clauses)
            if bits is None:
                bits = bits_of[clauses] = tuple((bitset(p), bitset(q)) for p, q in clauses)
            self.clause_bits[row] = bits
        offsets = self.clauses[0]  # rows without clauses have no clause facts to repeat
        at = self.clause_rows * 2
        self.clause_pos_rows = np.repeat(self.clause_rows, offsets[at + 2] - offsets[at])
        self.clause_neg_rows = np.repeat(self.clause_rows, offsets[at + 3] - offsets[at + 1])
        self.pre_index = self.add_index = self.delete_index = b""
        if _fixpoint is not None:
            n = len(st.facts)
            self.pre_index = _fixpoint.index(st.size, st.pre, st.pre.shape[1], n + 2)
            self.add_index = _fixpoint.index(st.size, st.add, st.add.shape[1], n)
            self.delete_index = _fixpoint.index(st.size, st.delete, st.delete.shape[1], n)

    def _row_cache(self) -> tuple:
        cache = self._cache
        if cache is None:  # one tuple, set at once: safe if calls interleave
            st = self._st
            cache = self._cache = (
                np.zeros((4, st.size), dtype=bool),  # per matrix: row filled in
                tuple(np.empty(m.shape, dtype=np.int64)
                      for m in (st.pre, st.pre_neg, st.add, st.delete)),
            )
        return cache

    def rows(self, rows: np.ndarray) -> tuple[np.ndarray, ...]:
        """The four matrices of these rows (computing the missing ones, kept per
        structure): the numpy fallback's path; compiled, `task_rows` sorts the kept rows
        afresh instead."""
        st, n = self._st, len(self._st.facts)
        done, matrices = self._row_cache()
        sources = (st.pre, st.pre_neg, st.add, st.delete)
        for k, (source, matrix) in enumerate(zip(sources, matrices, strict=True)):
            missing = rows[~done[k][rows]]  # per matrix: safe if calls interleave
            matrix[missing] = fact_matrix(np.take(source, missing, axis=0), n, None)
            done[k][missing] = True
        # np.take: ~3x faster than m[rows] for a row gather
        return tuple(np.take(m, rows, axis=0) for m in matrices)


def derived(st: GroundStructure) -> Derived:
    """The structure's derived arrays, made on first use and kept with the structure."""
    value = st.memo.get("derived")
    if value is None:
        value = st.memo["derived"] = Derived(st)
    return value  # type: ignore[return-value]


def _clause_csr(st: GroundStructure) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clause facts per row for `_fixpoint.relevant`: interleaved offsets (row r's
    positives start at [2r], its negatives at [2r + 1]) and the two fact lists."""
    counts = np.zeros((2, st.size + 1), dtype=np.int64)  # facts of row r at [:, r + 1]
    positives: list[int] = []
    negatives: list[int] = []
    flat: dict[tuple, tuple[list[int], list[int]]] = {}  # rows share clause lists
    rows = sorted(st.clauses)
    n_pos, n_neg = [], []
    for row in rows:
        clauses = st.clauses[row]
        facts = flat.get(clauses)
        if facts is None:
            facts = flat[clauses] = ([f for pos, _ in clauses for f in pos],
                                     [f for _, neg in clauses for f in neg])
        positives.extend(facts[0])
        negatives.extend(facts[1])
        n_pos.append(len(facts[0]))
        n_neg.append(len(facts[1]))
    at = np.array(rows, dtype=np.int64) + 1
    counts[0, at] = n_pos
    counts[1, at] = n_neg
    offsets = np.empty(2 * (st.size + 1), dtype=np.int64)
    np.cumsum(counts[0], out=offsets[0::2])
    np.cumsum(counts[1], out=offsets[1::2])
    return (offsets, np.array(positives, dtype=np.int64),
            np.array(negatives, dtype=np.int64))


def task_rows(st: GroundStructure, kept_rows: np.ndarray, read: np.ndarray
              ) -> tuple[np.ndarray, ...]:
    """The kept rows' (pre, pre_neg, add, delete) fact-id matrices, with add and delete
    facts that `read` (bool over fact ids + pads) does not mark removed: what
    `fact_matrix(rows, n, read)` gives. Compiled, the rows are sorted afresh into k-row
    arrays (cheaper than filling, then gathering from, the structure-wide cache). No bitset
    words: the native core keeps an action's non-zero words only, from these ids."""
    if _fixpoint is None:
        return _task_rows_numpy(st, kept_rows, read)
    n = len(st.facts)
    n_words = n // 64 + 1
    rows = np.ascontiguousarray(kept_rows, dtype=np.int64)
    read_facts = np.ascontiguousarray(read[:n], dtype=bool)
    matrices = []
    for source, mask in ((st.pre, None), (st.pre_neg, None), (st.add, read_facts),
                         (st.delete, read_facts)):
        out = np.empty((len(rows), source.shape[1]), dtype=np.int64)
        _fixpoint.gather_rows(st.size, source, source.shape[1], n, n_words, rows, len(rows),
                              mask, out, None)
        matrices.append(out)
    return tuple(matrices)


def _task_rows_numpy(st: GroundStructure, kept_rows: np.ndarray, read: np.ndarray
                     ) -> tuple[np.ndarray, ...]:
    pre, pre_neg, add, delete = derived(st).rows(kept_rows)
    matrices = [pre, pre_neg]
    for m in (add, delete):
        keep = (m >= 0) & read[m]
        if not np.array_equal(keep, m >= 0):  # drop unread facts, keep each row sorted
            m = np.where(keep, m, _BIG)
            m.sort(axis=1)
            m[m == _BIG] = -1
        matrices.append(m)
    return tuple(matrices)


def reachable(st: GroundStructure, init: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    """Relaxed reachability (negative preconditions and clauses ignored) over the rows in
    `allowed`: the rows that may ever apply. `init` is a boolean array over fact ids + pads."""
    if _fixpoint is None:
        return reachable_numpy(st, init, allowed)
    n = len(st.facts)
    flags = _fixpoint.reachable(
        st.size, st.pre, st.pre.shape[1], st.add, st.add.shape[1], n + 2, n + 1,
        np.ascontiguousarray(init, dtype=bool), np.ascontiguousarray(allowed, dtype=bool),
        derived(st).pre_index,
    )
    return np.frombuffer(flags, dtype=bool)


def reachable_numpy(st: GroundStructure, init: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    reached = init.copy()
    active = np.zeros(st.size, dtype=bool)
    waiting = np.flatnonzero(allowed)
    none = len(st.facts) + 1
    while len(waiting):
        ok = reached[st.pre[waiting]].all(axis=1)
        if not ok.any():
            break
        new = waiting[ok]
        waiting = waiting[~ok]
        active[new] = True
        before = int(reached.sum())
        reached[st.add[new]] = True
        reached[none] = False
        if int(reached.sum()) == before:
            break
    return active


def relevant(st: GroundStructure, allowed: np.ndarray, goal: int, goal_neg: int) -> np.ndarray:
    """Backward relevance: keep actions that add a fact needed true or delete one needed
    false, where needs grow by the kept actions' conditions. Dropping the rest loses no plan
    (they can be cut from any plan, which only lowers its cost and raises its probability)."""
    if _fixpoint is None:
        return relevant_numpy(st, allowed, goal, goal_neg)
    d = derived(st)
    offsets, positives, negatives = d.clauses
    goal_ids = ids_of(goal)
    goal_neg_ids = ids_of(goal_neg)
    flags = _fixpoint.relevant(
        st.size, len(st.facts), len(st.facts) + 2, st.pre, st.pre.shape[1], st.pre_neg,
        st.pre_neg.shape[1], offsets, positives, len(positives), negatives, len(negatives),
        np.ascontiguousarray(allowed, dtype=bool), goal_ids, len(goal_ids), goal_neg_ids,
        len(goal_neg_ids), d.add_index, d.delete_index,
    )
    return np.frombuffer(flags, dtype=bool)


def relevant_numpy(st: GroundStructure, allowed: np.ndarray, goal: int, goal_neg: int
                    ) -> np.ndarray:
    n = len(st.facts)
    need_true = np.zeros(n + 2, dtype=bool)
    need_false = np.zeros(n + 2, dtype=bool)
    need_true[ids_of(goal)] = True
    need_false[ids_of(goal_neg)] = True
    kept = np.zeros(st.size, dtype=bool)
    waiting = np.flatnonzero(allowed)
    while len(waiting):
        hit = need_true[st.add[waiting]].any(axis=1) | need_false[st.delete[waiting]].any(axis=1)
        if not hit.any():
            break
        new = waiting[hit]
        waiting = waiting[~hit]
        kept[new] = True
        need_true[st.pre[new]] = True
        need_false[st.pre_neg[new]] = True
        for row in new.tolist():
            for pos, neg in st.clauses.get(row, ()):
                need_true[list(pos)] = True
                need_false[list(neg)] = True
        need_true[n:] = False
        need_false[n:] = False
    return kept


