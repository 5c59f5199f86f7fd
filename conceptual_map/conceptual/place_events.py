"""Feed the place map's change events into a `ConceptualMap`.

Rooms bring their places and room-level size/shape evidence; rooms sharing a door are linked
(phi_rc); a vanished room is merged into the room that took over its places; placeholders carry
their open space and whether they are near a door hypothesis. Doors themselves only matter
through the rooms that list them.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

from conceptual_map.conceptual.facade import ConceptualMap
from conceptual_map.places.model import Change, EntityKind, MapEvent, Placeholder, Room


@dataclass(frozen=True)
class GeometryEvidence:
    """How room geometry becomes soft size/shape evidence, and what a nearby door means.

    Areas below `small_area_m2` read as small, above `large_area_m2` as large; elongation above
    `elongated_ratio` reads as elongated, below `square_ratio` as square. The matching value
    gets weight 1 and the others `other_weight` (a room's known area grows while exploring).
    """

    small_area_m2: float = 6.0
    large_area_m2: float = 20.0
    elongated_ratio: float = 2.0
    square_ratio: float = 1.3
    other_weight: float = 0.3
    p_door_near: float = 0.9

    def size(self, area: float) -> str:
        if area < self.small_area_m2:
            return "small"
        return "large" if area > self.large_area_m2 else "medium"

    def shape(self, elongation: float) -> str:
        if elongation > self.elongated_ratio:
            return "elongated"
        return "square" if elongation < self.square_ratio else "rectangular"


class PlaceMapFeed:
    """Applies batches of `MapEvent`s to a conceptual map; owns its room links (shared doors)."""

    def __init__(self, cmap: ConceptualMap, geometry: GeometryEvidence | None = None) -> None:
        self.cmap = cmap
        self.geometry = geometry or GeometryEvidence()
        self._room_doors: dict[str, frozenset[str]] = {}
        self._placeholders: dict[str, Placeholder] = {}

    def apply(self, events: Iterable[MapEvent]) -> None:
        """Apply one batch (as returned by one place-map update)."""
        events = list(events)
        for event in _of(events, EntityKind.ROOM, live=True):
            self._room_seen(event.entity)
        for event in _of(events, EntityKind.ROOM, live=False):
            self._room_gone(event.entity)
        for event in _of(events, EntityKind.PLACE, live=False):
            if self.cmap.graph.has_place(event.id):
                self.cmap.remove_place(event.id)
        for event in _of(events, EntityKind.PLACEHOLDER, live=True):
            self._placeholders[event.id] = event.entity
        for event in _of(events, EntityKind.PLACEHOLDER, live=False):
            self._placeholders.pop(event.id, None)
            if event.id in self.cmap.placeholders:
                self.cmap.remove_placeholder(event.id)
        self._sync_links()
        self._sync_placeholders()

    def _room_seen(self, room: Room) -> None:
        self.cmap.add_room(room.id)
        for place in sorted(room.places):
            if self._room_of(place) != room.id:
                self.cmap.add_place(place, room.id)
        self._room_doors[room.id] = room.doors
        properties = self.cmap.knowledge.properties
        for kind, value in (("size", self.geometry.size(room.area)),
                            ("shape", self.geometry.shape(room.elongation))):
            if kind in properties and value in properties[kind].values:
                weights = {v: self.geometry.other_weight for v in properties[kind].values}
                self.cmap.observe_room_property(room.id, kind, weights | {value: 1.0})

    def _room_gone(self, room: Room) -> None:
        self._room_doors.pop(room.id, None)
        if not self.cmap.graph.has_room(room.id):
            return
        heirs = Counter(
            owner for p in room.places if (owner := self._room_of(p)) not in (None, room.id)
        )
        if heirs:
            self.cmap.merge_rooms(heirs.most_common(1)[0][0], room.id)
        else:
            self.cmap.remove_room(room.id)

    def _room_of(self, place: str) -> str | None:
        graph = self.cmap.graph
        return graph.room_of(place) if graph.has_place(place) else None

    def _sync_links(self) -> None:
        wanted = {
            frozenset((a, b))
            for a, doors_a in self._room_doors.items()
            for b, doors_b in self._room_doors.items()
            if a < b and doors_a & doors_b
        }
        graph = self.cmap.graph
        present = {frozenset((a, b)) for a in graph.rooms for b in graph.neighbours(a)}
        for pair in present - wanted:
            self.cmap.disconnect_rooms(*sorted(pair))
        for pair in wanted - present:
            self.cmap.connect_rooms(*sorted(pair))

    def _sync_placeholders(self) -> None:
        for pid, ph in self._placeholders.items():
            room = self._room_of(ph.place) if ph.place is not None else None
            if room is None:
                continue
            p_door = self.geometry.p_door_near if ph.near_door else 0.0
            current = self.cmap.placeholders.get(pid)
            if current is None or (current.room, current.open_space_m2, current.p_door) != (
                room, ph.open_space, p_door
            ):
                self.cmap.add_placeholder(pid, room, ph.open_space, p_door)


def _of(events: list[MapEvent], kind: EntityKind, live: bool) -> list[MapEvent]:
    """Events of `kind` that appeared/changed (`live`) or vanished."""
    return [e for e in events if e.kind is kind and (e.change is not Change.VANISHED) == live]
