"""The robot's map as the trace's `map` events drew it (`reporting/snapshots.py`), for the
explanations: which room the robot mapped behind a placeholder it explored, and which objects
it found there (`explain_ledger.Ledger` judges room hypotheses by them)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

# m: a place this near where a placeholder stood is in the room behind it, once explored
# (the place map drops a place every metre along the path: one lies within about a metre of
# any spot the robot went to)
BEHIND_REACH = 1.5
# m: objects detected this near where a placeholder stood were found behind it (the open
# space a placeholder stands for is the unknown within 3 m: `PlaceMapConfig`)
FOUND_REACH = 3.0


class MapState:
    """The last value of each part of the trace's `map` events (`reporting/snapshots.py`): the
    places with their rooms, every placeholder's last position, the rooms' category beliefs,
    the known objects, and when each room and object first appeared."""

    def __init__(self) -> None:
        self.places: dict[str, tuple[float, float, str | None]] = {}
        self.placeholders: dict[str, tuple[float, float]] = {}  # last positions, kept
        self.rooms: dict[str, dict[str, float]] = {}
        self.objects: dict[str, tuple[str, float, float, str | None]] = {}
        self.since: dict[str, float] = {}  # room or object id -> when it first appeared

    def feed(self, event: Mapping[str, Any]) -> None:
        t = float(event.get("t") or 0.0)
        if isinstance(event.get("places"), list):
            self.places = {str(p[0]): (float(p[1]), float(p[2]), p[3])
                           for p in event["places"] if len(p) >= 4}
        for p in event.get("placeholders") or []:
            if len(p) >= 3:
                self.placeholders[str(p[0])] = (float(p[1]), float(p[2]))
        if isinstance(event.get("rooms"), Mapping):
            self.rooms = {str(k): dict(v) for k, v in event["rooms"].items()
                          if isinstance(v, Mapping)}
            for rid in self.rooms:
                self.since.setdefault(rid, t)
        if isinstance(event.get("objects"), list):
            self.objects = {str(o[0]): (str(o[1]), float(o[2]), float(o[3]), o[4])
                            for o in event["objects"] if len(o) >= 5}
            for oid in self.objects:
                self.since.setdefault(oid, t)

    def room_behind(self, placeholder: str) -> str | None:
        """The room of the place nearest to where `placeholder` last stood, within
        `BEHIND_REACH` m (None: no place there, the robot did not map that space)."""
        at = self.placeholders.get(placeholder)
        if at is None or not self.places:
            return None
        x, y, room = min(self.places.values(), key=lambda p: math.dist(p[:2], at))
        return room if math.dist((x, y), at) <= BEHIND_REACH else None

    def new_since(self, rid: str, t: float) -> bool:
        return self.since.get(rid, math.inf) >= t

    def found_near(self, placeholder: str, t: float
                   ) -> list[tuple[str, str, float, float, str | None]]:
        """Objects (id, label, x, y, room) that first appeared at `t` or later within
        `FOUND_REACH` m of where `placeholder` last stood."""
        at = self.placeholders.get(placeholder)
        if at is None:
            return []
        return [(oid, lab, x, y, where) for oid, (lab, x, y, where) in self.objects.items()
                if self.new_since(oid, t) and math.dist((x, y), at) <= FOUND_REACH]
