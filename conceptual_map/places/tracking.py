"""Keeping ids stable across updates: match new findings to what the map already holds."""

from __future__ import annotations

import math
from collections.abc import Hashable, Sequence
from typing import TypeVar

Old = TypeVar("Old", bound=Hashable)


def match_by_distance(
    old: dict[Old, tuple[float, float]],
    new: Sequence[tuple[float, float]],
    limit: float,
) -> dict[int, Old]:
    """Greedy nearest pairs (closest first) within `limit`: new index -> old key."""
    pairs = sorted(
        (math.dist(p, q), i, key)
        for i, p in enumerate(new)
        for key, q in old.items()
        if math.dist(p, q) <= limit
    )
    return _greedy(pairs)


def match_by_overlap(old: dict[Old, set[str]], new: Sequence[set[str]]) -> dict[int, Old]:
    """Greedy pairs by most shared members (largest first): new index -> old key."""
    pairs = sorted(
        (-len(members & prev), i, key)
        for i, members in enumerate(new)
        for key, prev in old.items()
        if members & prev
    )
    return _greedy(pairs)


def _greedy(pairs: list[tuple]) -> dict[int, Old]:
    taken: set = set()
    out: dict[int, Old] = {}
    for _, i, key in pairs:
        if i in out or key in taken:
            continue
        out[i] = key
        taken.add(key)
    return out
