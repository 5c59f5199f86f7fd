"""Place map: places along the robot's path, placeholders at frontiers, doors, rooms, events."""

from conceptual_map.places.config import PlaceMapConfig
from conceptual_map.places.frontiers import FrontierRegion, frontier_regions
from conceptual_map.places.model import (
    Change,
    Door,
    EntityKind,
    MapEvent,
    Place,
    Placeholder,
    Room,
)
from conceptual_map.places.place_map import PlaceMap

__all__ = [
    "Change",
    "Door",
    "EntityKind",
    "FrontierRegion",
    "MapEvent",
    "Place",
    "PlaceMap",
    "PlaceMapConfig",
    "Placeholder",
    "Room",
    "frontier_regions",
]
