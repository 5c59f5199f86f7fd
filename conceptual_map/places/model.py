"""The place map's entities and its change events: plain frozen dataclasses.

Other layers (the chain graph facade, the state builder) consume these without knowing how the
place map finds them. Ids are stable strings usable as PDDL object names (`place3`, `door1`).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

Point = tuple[float, float]


@dataclass(frozen=True)
class Place:
    """A spot the robot has been, dropped every ~1 m along its path."""

    id: str
    position: Point
    time: float


@dataclass(frozen=True)
class Placeholder:
    """A hypothetical place at a reachable free/unknown border (§2 of the active visual search
    paper by Göbelbecker et al.).

    `position` is where the robot can stand to look; `open_space` is the unknown area (m^2)
    behind the frontier within a few metres, the evidence for how much may lie beyond.
    """

    id: str
    position: Point
    frontier_centre: Point
    frontier_length: float
    open_space: float
    place: str | None
    near_door: str | None


@dataclass(frozen=True)
class Door:
    """A narrow opening the robot passed: the chord between its jambs, and whether it crossed."""

    id: str
    centre: Point
    width: float
    ends: tuple[Point, Point]
    confirmed: bool


@dataclass(frozen=True)
class Room:
    """Places connected without crossing a door, with the free area they share."""

    id: str
    places: frozenset[str]
    doors: frozenset[str]
    area: float  # m^2 of known free space
    elongation: float  # sqrt of the ratio of principal variances: 1 for a square, a/b for a*b


class EntityKind(Enum):
    PLACE = "place"
    PLACEHOLDER = "placeholder"
    DOOR = "door"
    ROOM = "room"


class Change(Enum):
    APPEARED = "appeared"
    CHANGED = "changed"
    VANISHED = "vanished"


@dataclass(frozen=True)
class MapEvent:
    """One thing in the place map appeared, changed or vanished; `entity` is its latest state."""

    kind: EntityKind
    change: Change
    id: str
    entity: Place | Placeholder | Door | Room
    time: float = 0.0
