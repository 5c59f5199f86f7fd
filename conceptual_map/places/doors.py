"""Door hypotheses from the robot's own grid: a short narrowing in a wall (Göbelbecker et al.,
"A Planning Approach to Active Visual Search in Large Environments", §2).

At each probe point, chords through the point are probed in many directions up to the first
occupied cell. The shortest chord is the opening's width across; it is a door when it is
narrower than ~1.5 m (double doors included), widens again a wall's thickness before and after
(a narrow corridor or a gap beside a long piece of furniture stays narrow for longer), and its
jambs continue as walls along the chord's line.

The place map probes the path the robot drove, the way from a place to each new frontier,
and the ridge of the free space around the robot (`PlaceMap._doors_in_view`: a room seen
through its door from a corridor is parted from the corridor before the robot goes in, and if
it never does); points off the path must see the space widen beside the opening in floor known
to be free, so the mouth of a corridor not yet looked into is no door.

A hypothesis may still be the gap between pieces of furniture, or between furniture and a
wall: the laser sees furniture as an outline round unseen (or occupied) inside, and an edge of
it in line with the chord passes for a wall. `between_walls` tells them apart once both sides
are seen: beside a door the jambs are thin walls with free floor on both of their faces.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.logodds import CellState
from conceptual_map.places.config import PlaceMapConfig

_ANGLES = np.linspace(0.0, np.pi, 24, endpoint=False)
_WIDENING = 0.3  # metres the chord must grow beside the door to count as short


@dataclass(frozen=True)
class Opening:
    """A narrow chord through a path point: its centre, width and direction (radians)."""

    centre: np.ndarray
    width: float
    angle: float

    @property
    def axis(self) -> np.ndarray:
        return np.array([np.cos(self.angle), np.sin(self.angle)])

    @property
    def normal(self) -> np.ndarray:
        return np.array([-np.sin(self.angle), np.cos(self.angle)])

    def ends(self) -> tuple[np.ndarray, np.ndarray]:
        half = 0.5 * self.width * self.axis
        return self.centre - half, self.centre + half


def chord_extents(
    grid: OccupancyGrid, points: np.ndarray, angles: np.ndarray, reach: float,
    known_only: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Distances (P, A) from each point to the first occupied cell along +axis and -axis
    (`known_only`: to the first cell not known to be free, the grid's outside included)."""
    state = grid.state_grid()
    steps = np.arange(1, int(np.ceil(reach / (0.5 * grid.resolution))) + 1) * 0.5 * grid.resolution
    axis = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    out = []
    for sign in (1.0, -1.0):
        probe = (
            points[:, None, None, :] + sign * axis[None, :, None, :] * steps[None, None, :, None]
        )
        cells = grid.to_cell(probe.reshape(-1, 2))
        inside = grid.inside(cells)
        blocked = np.full(cells.shape[0], known_only)
        hit = state[cells[inside, 0], cells[inside, 1]]
        blocked[inside] = hit != CellState.FREE if known_only else hit == CellState.OCCUPIED
        blocked = blocked.reshape(probe.shape[:3])
        first = np.where(blocked.any(axis=2), steps[np.argmax(blocked, axis=2)], np.inf)
        out.append(first)
    return out[0], out[1]


def openings_along(
    grid: OccupancyGrid, points: np.ndarray, config: PlaceMapConfig, seen_beside: bool = False
) -> list[Opening]:
    """Door-like openings at the given points (at most one per point).

    The jambs must also continue as straight walls along the chord: otherwise the gap between
    a table's corner and a wall, or a diagonal across a half-seen corner, looks like a door.
    `seen_beside`: the space must widen beside the opening in floor known to be free (for
    points the robot did not drive through: the mouth of a corridor not yet looked into
    would otherwise pass for a door).
    """
    if points.shape[0] == 0:
        return []
    cells = grid.to_cell(points)
    inside = grid.inside(cells)
    near_wall = np.zeros(points.shape[0], dtype=bool)  # a point mid-door is near both jambs
    near_wall[inside] = (
        grid.clearance()[cells[inside, 0], cells[inside, 1]] <= 0.5 * config.door_max_width
    )
    points = points[near_wall]
    if points.shape[0] == 0:
        return []
    plus, minus = chord_extents(grid, points, _ANGLES, config.probe_range)
    # the probe stops at the near border of a jamb's cell; the surface lies, on average,
    # half a cell further in on each side
    width = plus + minus + grid.resolution
    best = np.argmin(width, axis=1)
    rows = np.arange(points.shape[0])
    narrow = width[rows, best]
    keep = (narrow >= config.door_min_width) & (narrow <= config.door_max_width)
    found = []
    for k in np.nonzero(keep)[0]:
        angle = float(_ANGLES[best[k]])
        axis = np.array([np.cos(angle), np.sin(angle)])
        centre = points[k] + axis * 0.5 * (plus[k, best[k]] - minus[k, best[k]])
        opening = Opening(centre, float(narrow[k]), angle)
        if _is_short(grid, opening, config, seen_beside) and _in_wall(grid, opening):
            found.append(opening)
    return found


def _in_wall(grid: OccupancyGrid, opening: Opening, reach: float = 0.3) -> bool:
    """Occupied cells continue along the chord's line beyond both jambs (most of `reach`)."""
    occupied = grid.state_grid() == CellState.OCCUPIED
    steps = np.arange(0.05, reach + 1e-9, 0.025)
    across = np.array([-0.075, -0.025, 0.025, 0.075])
    for sign, end in zip((1.0, -1.0), (opening.ends()[1], opening.ends()[0]), strict=True):
        pts = (
            end[None, None, :]
            + sign * steps[:, None, None] * opening.axis
            + across[None, :, None] * opening.normal
        )
        cells = grid.to_cell(pts.reshape(-1, 2))
        inside = grid.inside(cells)
        hit = np.zeros(len(cells), dtype=bool)
        hit[inside] = occupied[cells[inside, 0], cells[inside, 1]]
        if hit.reshape(len(steps), len(across)).any(axis=1).mean() < 0.7:
            return False
    return True


def _is_short(grid: OccupancyGrid, opening: Opening, config: PlaceMapConfig,
              known_only: bool = False) -> bool:
    """The chord widens within `door_max_depth` on both sides of the opening (`known_only`:
    in floor known to be free)."""
    beside = np.stack(
        [opening.centre + s * config.door_max_depth * opening.normal for s in (1.0, -1.0)]
    )
    plus, minus = chord_extents(grid, beside, np.array([opening.angle]), config.probe_range,
                                known_only)
    return bool(np.all(plus[:, 0] + minus[:, 0] >= opening.width + _WIDENING))


def between_walls(grid: OccupancyGrid, ends: tuple, depth: float,
                  sides: Iterable[int] = (1, -1), state: np.ndarray | None = None) -> bool:
    """Whether the structure beyond both ends of the door chord `ends` (a to b) is a thin
    wall as seen from `sides` (+1: the side of the normal (-dy, dx) of b - a; -1: the other):
    at most points 0.1-0.3 m beyond each jamb, along the chord's line, free cells lie within
    `depth` (a door's `door_max_depth`: a wall is thinner) on each of those sides of the line.
    The edge of a table, shelf or chair in line with the chord has its unseen (or occupied)
    inside on one side. Only the sides the robot has been on are asked: a wall's far face
    near the jambs is hidden from the near side, the door seen but not passed through."""
    states = grid.state_grid() if state is None else state
    a, b = np.asarray(ends[0], dtype=float), np.asarray(ends[1], dtype=float)
    length = float(np.linalg.norm(b - a))
    if length <= 0.0:
        return False
    axis = (b - a) / length
    normal = np.array([-axis[1], axis[0]])
    beyond = np.array([0.1, 0.2, 0.3])
    across = np.arange(0.5 * grid.resolution, depth + 1e-9, 0.5 * grid.resolution)
    for end, sign in ((b, 1.0), (a, -1.0)):
        base = end[None, :] + sign * beyond[:, None] * axis  # (3, 2) points on the wall line
        thin = np.ones(len(beyond), dtype=bool)
        for side in sorted({float(np.sign(v)) for v in sides} - {0.0}):
            pts = base[:, None, :] + side * across[None, :, None] * normal
            cells = grid.to_cell(pts.reshape(-1, 2))
            inside = grid.inside(cells)
            free = np.zeros(len(cells), dtype=bool)
            free[inside] = states[cells[inside, 0], cells[inside, 1]] == CellState.FREE
            thin &= free.reshape(len(beyond), len(across)).any(axis=1)
        if thin.mean() < 0.5:
            return False
    return True


def crossings(points: np.ndarray, ends: tuple[np.ndarray, np.ndarray]) -> int:
    """How often the polyline through `points` (K, 2) crosses the door chord. Points exactly on
    the door line count as on its positive side, so every place belongs to exactly one side."""
    pts = np.asarray(points, dtype=float)
    p, q = np.asarray(ends[0], dtype=float), np.asarray(ends[1], dtype=float)
    d = q - p
    normal = np.array([-d[1], d[0]])
    side = (pts - p) @ normal
    a, b = side[:-1], side[1:]
    switch = (a >= 0) != (b >= 0)
    if not switch.any():
        return 0
    t = a[switch] / (a[switch] - b[switch])
    x = pts[:-1][switch] + t[:, None] * (pts[1:][switch] - pts[:-1][switch])
    u = (x - p) @ d / (d @ d)
    return int(np.count_nonzero((u >= -0.05) & (u <= 1.05)))
