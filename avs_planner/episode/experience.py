"""What a finished episode teaches the experience store (`conceptual_map/knowledge/
experience.py`), read from the robot's mind only: its conceptual map's rooms, their category
beliefs and door links, and the object ledger's found objects and looks. Nothing here reads
the simulator.

A room counts under its most probable category when the mind believes it with at least
`CONFIDENT` (0.8); rooms it was less sure of count nothing. Weighting every room's counts by
its category belief would spread a kitchen's cups over offices whenever the classifier
hesitated, teaching offices to hold cups; leaving unsure rooms out loses some evidence but
adds none that is wrong by construction.

Per room and label the robot looked for there (searches and frames taken in passing, the
ledger's looks), the exposure is the share of the room's `label` objects those looks would
have seen (1 - the ledger's `remaining`), and the found count the objects of that label found
directly in the room; per known support whose space the knowledge lists for the label, the
same for the space on/in it. A label nobody looked for in a room teaches nothing there: a
table seen in passing has no record of how much was looked at, and counting it would only
ever raise the table rate.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from avs_planner.episode.mind import Mind
from conceptual_map.knowledge.experience import Evidence

CONFIDENT = 0.8
"""The category belief at or above which a room counts under its category."""


def room_categories(mind: Mind, confident: float = CONFIDENT) -> dict[str, str]:
    """Room id -> its most probable category, for the rooms believed that with `confident`."""
    cmap = mind.cmap
    out = {}
    for room in cmap.graph.rooms:
        belief = cmap.room_marginal(room)
        k = int(np.argmax(belief))
        if belief[k] >= confident:
            out[room] = cmap.knowledge.categories[k]
    return out


def episode_evidence(mind: Mind, confident: float = CONFIDENT) -> Evidence:
    """The counts one episode adds to the experience store (module doc)."""
    cmap = mind.cmap
    ledger = cmap.objects
    categories = room_categories(mind, confident)
    rooms: dict[tuple[str, str], tuple[float, float]] = {}
    supports: dict[tuple[str, str, str, str], tuple[float, float]] = {}
    for label in sorted(cmap.knowledge.labels):
        for room in sorted(ledger.looked_rooms(label) & set(categories)):
            category = categories[room]
            _add(rooms, (label, category), ledger.count(room, label),
                 1.0 - ledger.remaining(room, label))
            for space in ledger.sublocations(room, label):
                seen = 1.0 - ledger.remaining(space, label)
                found = ledger.count(space, label)
                if seen <= 0.0 and not found:
                    continue
                support = ledger.objects[space.object_id].label
                _add(supports, (label, space.relation, support, category), found, seen)
    neighbours: Counter[tuple[str, str]] = Counter()
    for room, category in categories.items():
        for other in cmap.graph.neighbours(room):
            if other in categories and room < other:
                a, b = sorted((category, categories[other]))
                neighbours[(a, b)] += 1
    return Evidence(rooms=rooms, supports=supports,
                    categories=dict(Counter(categories.values())),
                    neighbours=dict(neighbours))


def _add(table: dict, key: tuple, found: float, exposure: float) -> None:
    if not found and exposure <= 0.0:
        return
    n, e = table.get(key, (0.0, 0.0))
    table[key] = (n + float(found), e + float(exposure))
