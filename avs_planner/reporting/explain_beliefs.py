"""The mind's beliefs at the end of an episode, for its explanation (`final_beliefs` in
explanation.json): only the finished episode knows them, so a rebuilt explanation lacks them."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from avs_planner.reporting.explain_terms import rounded


def final_beliefs(mind: Any, target: str) -> dict[str, Any]:
    """The mind's beliefs at the end of an episode: each room of its place map with its most
    probable category (`believed`, `p`), its likeliest categories, P(target in it) and the
    objects known in it; each placeholder's belief about what lies behind it."""
    cmap, pm = mind.cmap, mind.place_map
    rooms: dict[str, Any] = {}
    for rid in sorted(pm.rooms, key=_natural):
        objects = [o.label for o in mind.objects.values() if o.room == rid]
        if not cmap.graph.has_room(rid):
            rooms[rid] = {"believed": None, "p": None, "category": {}, "p_target": None,
                          "objects": objects}
            continue
        category = cmap.room_category(rid)
        try:
            p_target = cmap.p_object_at(target, rid)
        except Exception:  # noqa: BLE001 - a label the knowledge base does not know
            p_target = None
        believed = max(category, key=category.get)
        rooms[rid] = {"believed": believed, "p": rounded(category[believed]),
                      "category": _top(category), "p_target": rounded(p_target),
                      "objects": objects}
    placeholders: dict[str, Any] = {}
    for pid in sorted(pm.placeholders):
        try:
            category = cmap.placeholder_category(pid)
        except Exception:  # noqa: BLE001 - a placeholder the conceptual map has not seen yet
            continue
        placeholders[pid] = {"category": _top(category)}
    return {"rooms": rooms, "placeholders": placeholders}


def _natural(name: str) -> tuple[str, int]:
    """room2 before room10."""
    head = name.rstrip("0123456789")
    tail = name[len(head):]
    return head, int(tail) if tail else -1


def _top(dist: Mapping[str, float], n: int = 4) -> dict[str, float]:
    items = sorted(dist.items(), key=lambda kv: -kv[1])[:n]
    return {k: round(float(v), 4) for k, v in items}
