"""How the robot's placeholders ended, read from its own map: the evidence that calibrates the
placeholder model to the building (`conceptual_map/conceptual/calibration.py`).

A placeholder vanishes when its frontier is explored (or re-derived too far from where it
was). From then on it waits here, with the evidence it vanished with, until the map tells
what lay behind it: the point `PROBE` m beyond its frontier's centre, away from where the
robot would have stood to look, is

- still unknown: it waits (it may never be seen; then it says nothing);
- occupied (a wall, furniture): no new room;
- free and a room's floor: a new room when that room did not exist before the placeholder
  vanished (after merges), else no new room (the frontier opened onto its own room or one
  the robot knew);
- free but no room's yet (beyond a door not passed): it waits for the room to be entered.

Only the mind's own grid and place map are read, never the simulator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from conceptual_map.conceptual import ConceptualMap, PlaceholderEvidence
from conceptual_map.metric import OccupancyGrid
from conceptual_map.metric.logodds import CellState
from conceptual_map.places import MapEvent, PlaceMap
from conceptual_map.places.model import Change, EntityKind

PROBE = 1.0  # m beyond the frontier's centre: the space the placeholder stood for
REACH = 0.5  # m: the free cell nearest the probe that tells its room (`PlaceMap.room_at`)


@dataclass(frozen=True)
class Pending:
    """A vanished placeholder whose outcome the map does not tell yet."""

    evidence: PlaceholderEvidence
    probe: tuple[float, float]
    rooms_before: frozenset[str]


class PlaceholderOutcomes:
    """Vanished placeholders, until the map tells what lay behind each (module doc)."""

    def __init__(self) -> None:
        self.pending: dict[str, Pending] = {}
        self.resolved = 0

    def snapshot(self, cmap: ConceptualMap, place_map: PlaceMap) -> tuple:
        """What a batch of place-map events may need: the placeholders' evidence and the
        rooms, taken before the batch is applied (a vanished placeholder's evidence is gone
        after it)."""
        return dict(cmap.placeholders), dict(place_map.placeholders), frozenset(place_map.rooms)

    def update(self, snapshot: tuple, events: list[MapEvent], cmap: ConceptualMap,
               place_map: PlaceMap, grid: OccupancyGrid) -> int:
        """Queue the placeholders `events` made vanish, then record every queued outcome the
        map now tells (`ConceptualMap.observe_placeholder_outcome`); returns how many."""
        evidence, entities, rooms = snapshot
        for event in events:
            if (event.kind is EntityKind.PLACEHOLDER and event.change is Change.VANISHED
                    and event.id in evidence and event.id in entities):
                ph = entities[event.id]
                self.pending[event.id] = Pending(evidence[event.id],
                                                 _probe(ph.position, ph.frontier_centre), rooms)
        if not self.pending:
            return 0
        states = grid.state_grid()
        told = 0
        for pid, pending in list(self.pending.items()):
            outcome = _outcome(pending, cmap, place_map, grid, states)
            if outcome is None:
                continue
            del self.pending[pid]
            cmap.observe_placeholder_outcome(pending.evidence, outcome)
            told += 1
        self.resolved += told
        return told


def _probe(position: tuple[float, float], centre: tuple[float, float]) -> tuple[float, float]:
    """`PROBE` m beyond the frontier's centre, on the line from the placeholder's standpoint."""
    dx, dy = centre[0] - position[0], centre[1] - position[1]
    n = math.hypot(dx, dy)
    if n < 1e-9:
        return float(centre[0]), float(centre[1])
    return centre[0] + PROBE * dx / n, centre[1] + PROBE * dy / n


def _outcome(pending: Pending, cmap: ConceptualMap, place_map: PlaceMap,
             grid: OccupancyGrid, states: np.ndarray) -> bool | None:
    """Whether a new room lay behind the placeholder, or None while the map does not tell."""
    cell = grid.to_cell(np.asarray([pending.probe], dtype=float))[0]
    if not (0 <= cell[0] < states.shape[0] and 0 <= cell[1] < states.shape[1]):
        return None
    state = states[cell[0], cell[1]]
    if state == CellState.UNKNOWN:
        return None
    if state == CellState.OCCUPIED:
        return False
    room = place_map.room_at(grid, pending.probe, reach=REACH, nearest_place=False)
    if room is None:
        return None
    known = set(pending.rooms_before)
    known |= {r for r in (cmap.current_room(b) for b in pending.rooms_before) if r is not None}
    return room not in known
