"""Which grid cells a straight ray passes through, for many rays at once (any dimension).

Exact traversal without a Python loop per ray: a ray crosses a cell border whenever one of its
coordinates passes an integer. All crossing parameters of all rays are computed, padded, and
sorted; the midpoint between consecutive crossings lies inside exactly one traversed cell.
`traverse_reference` is the textbook per-ray walk (Amanatides & Woo), kept as the oracle for
tests and the reference in the benchmark.
"""

from __future__ import annotations

import math

import numpy as np

_MAX_ELEMENTS = 2_000_000  # bound on rays x crossings held in memory at once


def traverse(starts: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cells crossed by segments start->end given in cell units (cell i spans [i, i+1)).

    Returns (ray_index (M,), cells (M, D) int64); each ray lists each cell it enters once,
    including the cells holding its start and its end.
    """
    starts = np.asarray(starts, dtype=float)
    ends = np.asarray(ends, dtype=float)
    if starts.shape[0] == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, starts.shape[1]), dtype=np.int64)
    span = np.abs(np.floor(ends) - np.floor(starts)).sum(axis=1).max() + 2
    chunk = max(1, int(_MAX_ELEMENTS // span))
    parts = [
        _traverse_chunk(starts[i : i + chunk], ends[i : i + chunk], offset=i)
        for i in range(0, starts.shape[0], chunk)
    ]
    rays = np.concatenate([p[0] for p in parts])
    cells = np.concatenate([p[1] for p in parts])
    return rays, cells


def _traverse_chunk(a: np.ndarray, b: np.ndarray, offset: int) -> tuple[np.ndarray, np.ndarray]:
    delta = b - a
    params = [np.zeros((a.shape[0], 1)), np.ones((a.shape[0], 1))]
    for axis in range(a.shape[1]):
        params.append(_crossings(a[:, axis], b[:, axis], delta[:, axis]))
    t = np.sort(np.concatenate(params, axis=1), axis=1)
    valid = t[:, 1:] > t[:, :-1]
    mid = 0.5 * (t[:, 1:] + t[:, :-1])
    rows, cols = np.nonzero(valid)
    points = a[rows] + mid[rows, cols, None] * delta[rows]
    return rows + offset, np.floor(points).astype(np.int64)


def _crossings(a: np.ndarray, b: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Parameters t in (0, 1) where the coordinate a + t*d passes an integer; padded with 1."""
    lo = np.floor(np.minimum(a, b)) + 1.0
    count = np.maximum(0.0, np.ceil(np.maximum(a, b)) - lo).astype(np.int64)
    width = int(count.max()) if count.size else 0
    if width == 0:
        return np.ones((a.shape[0], 0))
    planes = lo[:, None] + np.arange(width)[None, :]
    safe_d = np.where(d == 0.0, 1.0, d)
    t = (planes - a[:, None]) / safe_d[:, None]
    inside = np.arange(width)[None, :] < count[:, None]
    return np.where(inside, np.clip(t, 0.0, 1.0), 1.0)


def traverse_reference(start: np.ndarray, end: np.ndarray) -> list[tuple[int, ...]]:
    """Cells crossed by one segment (cell units), walked one border at a time in Python."""
    cell = [math.floor(v) for v in start]
    last = [math.floor(v) for v in end]
    step, t_max, t_delta = [], [], []
    for s, e, c in zip(start, end, cell, strict=True):
        d = e - s
        step.append(1 if d > 0 else -1)
        if d == 0:
            t_max.append(math.inf)
            t_delta.append(math.inf)
            continue
        border = c + 1 if d > 0 else c
        t_max.append((border - s) / d)
        t_delta.append(abs(1.0 / d))
    cells = [tuple(cell)]
    while cell != last:
        axis = min(range(len(cell)), key=t_max.__getitem__)
        if t_max[axis] > 1.0:
            break
        cell[axis] += step[axis]
        t_max[axis] += t_delta[axis]
        cells.append(tuple(cell))
    return cells
