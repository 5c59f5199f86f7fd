"""How the grounding structure lays out rows of fact ids, and their bitsets.

Condition and effect arrays are padded to a common width with two codes (`_PAD_TRUE`, a fact
that always holds, and `_PAD_NONE`, one nothing reads or makes true) until the facts are
numbered; then rows are read back as sorted unique fact matrices (`fact_matrix`) or as Python
int bitsets for the Python search and heuristics (`bitset`, `_row_masks`, which goes through
little-endian uint64 words, `bit_words`). The native core takes the fact matrices and keeps an
action's non-zero words itself (`native.packed_rows`). The structure, its row compilation, the
derived arrays (`derived.py`) and the native packing (`native.py`) all share these layouts.
"""

from __future__ import annotations

import numpy as np

_PAD_TRUE = -1  # padding code of precondition arrays (an always-true fact)
_PAD_NONE = -2  # padding code of the other arrays (a fact nothing reads or makes true)


def _pad(lists: list[list[int]], pad: int) -> np.ndarray:
    """Lists of codes as one matrix, each row filled up to the longest with `pad`."""
    width = max((len(x) for x in lists), default=0)
    out = np.full((len(lists), width), pad, dtype=np.int64)
    for i, x in enumerate(lists):
        out[i, : len(x)] = x
    return out


def _row_masks(matrix: np.ndarray, n: int) -> list[int]:
    """Each row's fact ids (>= 0; -1 is padding) as a Python int bitset."""
    words = bit_words(matrix, n)
    data, size = words.tobytes(), words.shape[1] * 8
    return [int.from_bytes(data[i:i + size], "little") for i in range(0, len(data), size)]


def bit_words(matrix: np.ndarray, n_facts: int) -> np.ndarray:
    """Each row's fact ids (>= 0; -1 is padding) as little-endian uint64 words, one spare bit
    so that n_facts = 0 still has a word (the layout of the native core's states)."""
    words = n_facts // 64 + 1
    out = np.zeros((matrix.shape[0], words), dtype="<u8")
    rows, cols = np.nonzero(matrix >= 0)
    facts = matrix[rows, cols]
    np.bitwise_or.at(out, (rows, facts >> 6),
                     np.left_shift(np.uint64(1), (facts & 63).astype(np.uint64)))
    return out


def bitset(ids) -> int:
    """A Python int bitset of fact ids."""
    bits = 0
    for i in ids:
        bits |= 1 << i
    return bits


def fact_matrix(ids: np.ndarray, n: int, read: np.ndarray | None) -> np.ndarray:
    """Rows of fact ids sorted and unique, padding (ids >= n) and, if `read` is given,
    facts nothing reads replaced by -1 at the end of the row."""
    big = np.iinfo(np.int64).max
    valid = ids < n
    if read is not None:
        valid[valid] = read[ids[valid]]
    out = np.where(valid, ids, big)
    out.sort(axis=1)
    if out.shape[1] > 1:
        dup = np.zeros(out.shape, dtype=bool)
        dup[:, 1:] = out[:, 1:] == out[:, :-1]
        out[dup] = big
        out.sort(axis=1)
    out[out == big] = -1
    return out
