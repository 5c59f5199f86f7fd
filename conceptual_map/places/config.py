"""Tunable distances of the place map, in metres (defaults suit a Pioneer in an office)."""

from __future__ import annotations

from dataclasses import dataclass, fields

from conceptual_map.errors import MapError


@dataclass(frozen=True)
class PlaceMapConfig:
    place_spacing: float = 1.0  # a new place once the robot is this far from every place
    robot_radius: float = 0.25  # for reachability and straight-line edges
    # the slimmest disc the robot may try to squeeze through a gap with (its footprint less
    # the grid's under-estimate of clearance); free space it reaches only this way still gets
    # placeholders (the width is uncertain until tried: a touch says no). None: robot_radius
    squeeze_radius: float | None = None
    edge_max_length: float = 1.6  # straight-line edges between places up to this long
    door_max_width: float = 1.5  # openings narrower than this are door hypotheses
    door_min_width: float = 0.5
    door_max_depth: float = 0.35  # a door is a short narrowing (a wall), not a narrow corridor
    door_merge_distance: float = 0.5
    # door hypotheses are also looked for in the mapped free space this close to the robot,
    # where it narrows (`PlaceMap._doors_in_view`): about the laser's range
    door_view_radius: float = 5.0
    probe_range: float = 1.5  # how far the opening probe looks for jambs
    reach_tolerance: float = 0.6  # frontier cells this close to reachable space count
    min_frontier_length: float = 0.3
    min_open_space: float = 0.5  # m^2 of unknown behind a frontier for a placeholder
    open_space_radius: float = 3.0
    placeholder_match_distance: float = 1.0
    # free space beyond a mapped door from every place, or this far from all places, is
    # unvisited; a region of at least this area is a placeholder (a room seen, not entered)
    visit_radius: float = 3.0
    min_unvisited_area: float = 1.5
    trajectory_step: float = 0.05

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None and f.name == "squeeze_radius":
                continue
            if not value > 0:
                raise MapError(f"PlaceMapConfig.{f.name} must be positive, got {value!r}")
        if self.door_min_width >= self.door_max_width:
            raise MapError("PlaceMapConfig: door_min_width must be below door_max_width")
        if self.squeeze_radius is not None and self.squeeze_radius > self.robot_radius:
            raise MapError(f"PlaceMapConfig.squeeze_radius ({self.squeeze_radius}) must not "
                           f"exceed robot_radius ({self.robot_radius})")

    @property
    def reach_radius(self) -> float:
        """The disc whose reachable space gets placeholders: `squeeze_radius` if set."""
        return self.robot_radius if self.squeeze_radius is None else self.squeeze_radius
