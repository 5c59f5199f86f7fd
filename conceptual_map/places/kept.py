"""A place map kept between runs: `export` gives what a later run needs as plain data
(JSON-safe), `restore` rebuilds a map from it (the building memory,
`avs_planner/episode/memory.py`). Places, the edges between places with the path driven
along them, door openings with the sides the robot saw of each, rooms and the id counters
are kept; placeholders are not (the next `follow` or `refresh` derives them from the grid).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from conceptual_map.errors import MapError
from conceptual_map.places.doors import Opening
from conceptual_map.places.model import Change, EntityKind, MapEvent, Place, Room

if TYPE_CHECKING:
    from conceptual_map.places.place_map import PlaceMap


def export(pm: PlaceMap) -> dict[str, Any]:
    """What a later run needs to go on from this map, as plain data (JSON-safe): places,
    the edges between places (with the path driven along them), door openings and the
    sides the robot saw of each, rooms and the id counters. Placeholders are left out:
    the next `follow` (or `refresh`) derives them again from the grid."""
    edges = []
    for u, v, data in pm.graph.edges(data=True):
        if u in pm.places and v in pm.places:
            trace = data.get("trace")
            edges.append([u, v, bool(data.get("traversed")),
                          None if trace is None else np.round(trace, 3).tolist()])
    return {
        "places": {k: [p.position[0], p.position[1], p.time]
                   for k, p in pm.places.items()},
        "edges": edges,
        "openings": {k: [float(o.centre[0]), float(o.centre[1]), float(o.width),
                         float(o.angle), sorted(pm._sides.get(k, ()))]
                     for k, o in pm._openings.items()},
        "rooms": {k: {"places": sorted(r.places), "doors": sorted(r.doors),
                      "area": r.area, "elongation": r.elongation}
                  for k, r in pm.rooms.items()},
        "counters": dict(pm._counters),
    }


def restore(pm: PlaceMap, data: Mapping[str, Any]) -> tuple[PlaceMap, list[MapEvent]]:
    """`pm`, a fresh map, rebuilt from `export`'s data, and the events that bring a fresh
    conceptual map up to it (every room appears). The robot is at no place until its next
    `follow` (`PlaceMap.relocate`). A `MapError` names what is wrong with malformed data."""
    try:
        for pid, (x, y, t) in data["places"].items():
            pm.places[pid] = Place(str(pid), (float(x), float(y)), float(t))
            pm.graph.add_node(pid, kind="place", pos=pm.places[pid].position)
        for u, v, traversed, trace in data["edges"]:
            if u not in pm.places or v not in pm.places:
                raise MapError(f"edge {u}-{v} names a place the map does not hold")
            length = math.dist(pm.places[u].position, pm.places[v].position)
            pm.graph.add_edge(u, v, length=length, traversed=bool(traversed), door=None,
                              trace=None if trace is None else np.asarray(trace, float))
        for did, (cx, cy, width, angle, sides) in data["openings"].items():
            pm._openings[did] = Opening(np.array([cx, cy], dtype=float), float(width),
                                        float(angle))
            pm._sides[did] = {int(s) for s in sides}
            pm.doors[did] = pm._door_from(did)
        for rid, room in data["rooms"].items():
            places = frozenset(room["places"])
            if not places <= set(pm.places):
                raise MapError(f"room {rid} lists places the map does not hold")
            pm.rooms[rid] = Room(str(rid), places, frozenset(room["doors"]),
                                 float(room["area"]), float(room["elongation"]))
        pm._counters = {str(k): int(v) for k, v in data["counters"].items()}
    except MapError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise MapError(f"a kept place map is malformed: {type(exc).__name__}: {exc}"
                       ) from None
    events = [MapEvent(EntityKind.ROOM, Change.APPEARED, rid, room)
              for rid, room in pm.rooms.items()]
    return pm, events
