"""Place map: places along the robot's path, placeholders at frontiers, doors, rooms, events.

    grid, place_map = OccupancyGrid(), PlaceMap(PlaceMapConfig(robot_radius=0.3))
    grid.integrate_scan(scan)                              # after every laser scan
    events = place_map.follow(grid, poses_since_last_call, time=scan.time)
    # events: MapEvent(kind=PLACE|PLACEHOLDER|DOOR|ROOM, change=APPEARED|CHANGED|VANISHED, ...)
"""

from conceptual_map.places.config import PlaceMapConfig
from conceptual_map.places.exploration import ExplorationResult, ExplorationStatus, Explorer
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
    "ExplorationResult",
    "ExplorationStatus",
    "Explorer",
    "FrontierRegion",
    "MapEvent",
    "Place",
    "PlaceMap",
    "PlaceMapConfig",
    "Placeholder",
    "Room",
    "frontier_regions",
]
