"""CREATEVIEWCONES: candidate views for (label, relation, location), weighted and covering.

In a room, views stand at the room's places, and on its free floor a metre apart, and look in
eight directions; the occupied and unknown cells bordering the room's free floor are where
objects (and their supports) may be, and a greedy covering set keeps the views that add the
most such cells, each weighted by the share it adds of P(ObjectAt). The cells are the whole
room's, however far from where the robot has stood: when they were only those within the
camera's range of the room's places, a kitchen whose places lay along one wall was "searched"
without its far counter, the miss lowered P(cup in kitchen) as if the whole room had been
looked at, and the robot left the cup behind.

On a support, views stand around it, facing it, head tilted at where the knowledge puts the
label there: its top (`on`), its inside (`in`: a cup in a shelf), or between the two when it
lists both (`support_relations`); a search of a support looks for the label on it and in it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from avs_planner.dt import ViewCone
from avs_planner.episode.mind import KnownObject, Mind
from conceptual_map.conceptual import RelatedSpace
from conceptual_map.metric import CellState

ABOVE_TOP = 0.3  # m above a support's top where an object on it is looked for


@dataclass(frozen=True)
class CameraModel:
    """What the robot knows of its own camera: height, fields of view, recognition range."""

    height: float
    hfov: float
    detect_range: float
    look_distance: float = 2.0  # m: where an in-room view aims its tilt
    support_height: float = 0.7  # m: assumed top of a support before one is known
    vfov: float | None = None  # rad; None: the vertical field of view is not checked


@dataclass(frozen=True)
class ConeSet:
    """The cones of one CREATEVIEWCONES and the fraction of the location they cover."""

    cones: tuple[ViewCone, ...]
    coverage: float
    probability: float


def room_cones(mind: Mind, room: str, label: str, p_total: float, camera: CameraModel,
               key: str, max_cones: int = 6, min_gain: float = 0.03) -> ConeSet:
    """Greedy covering set of views from the room's places over its candidate cells."""
    places = standpoints(mind, room)
    cells = _room_cells(mind, room)
    if not places or len(cells) == 0:
        return ConeSet((), 0.0, p_total)
    tilt = -math.atan2(camera.height - camera.support_height, camera.look_distance)
    candidates = [(x, y, k * math.pi / 4) for x, y in places for k in range(8)]
    masks = [_in_wedge(cells, c, camera) for c in candidates]
    covered = np.zeros(len(cells), dtype=bool)
    chosen: list[tuple[tuple[float, float, float], float]] = []
    while len(chosen) < max_cones:
        gains = [int(np.count_nonzero(m & ~covered)) for m in masks]
        best = int(np.argmax(gains))
        if gains[best] < min_gain * len(cells):
            break
        chosen.append((candidates[best], gains[best] / len(cells)))
        covered |= masks[best]
    coverage = float(covered.mean())
    cones = tuple(
        ViewCone(f"{key}-{i}", pose, p_total * share, head=(0.0, tilt))
        for i, (pose, share) in enumerate(chosen)
    )
    return ConeSet(cones, coverage, p_total)


def support_relations(mind: Mind, label: str, support_label: str) -> tuple[str, ...]:
    """Where a search of a `support_label` looks for `label`: the relations the knowledge
    lists for the pair (`on` its top, `in` it), in `RELATIONS` order; `("on",)` when it lists
    none (the planner's support search is `on`)."""
    return mind.cmap.knowledge.support_relations(label).get(support_label) or ("on",)


def support_spaces(mind: Mind, label: str, oid: str) -> list[RelatedSpace]:
    """The related spaces of the known object `oid` a search of it for `label` looks at
    (`on` it for an object the mind no longer knows: the conceptual map then says so)."""
    obj = mind.objects.get(oid)
    relations = support_relations(mind, label, obj.label) if obj is not None else ("on",)
    return [RelatedSpace(r, oid) for r in relations]


def p_at_support(mind: Mind, label: str, oid: str, another: bool = False) -> float:
    """P(at least one `label` on or in the known object `oid`, where the knowledge lists it),
    after the looks so far: the lambdas left in its spaces add up under each room
    category before the category belief averages them (one space: the conceptual map's
    `p_object_at` of it). `another`: one more beyond those found there (a task counting
    every instance: `ConceptualMap.p_object_at`)."""
    cmap = mind.cmap
    spaces = support_spaces(mind, label, oid)
    per_space = [cmap.p_object_at_per_category(label, space, include_sublocations=False,
                                               another=another)
                 for space in spaces]
    if len(per_space) == 1:
        return cmap.p_object_at(label, spaces[0], include_sublocations=False,
                               another=another)
    lam = sum(cmap.mass(label, p) for p in per_space)
    room = cmap.objects.objects[oid].room
    return float(cmap.room_marginal(room) @ cmap.p_any(label, lam))


def aim_height(top: float, relations: tuple[str, ...]) -> float:
    """The height a view of a support with its top at `top` aims at: the top itself for
    `on` alone; with `in`, the middle of the band the label may be in (from half the
    support's height up to its top, and up to `ABOVE_TOP` above it if also `on`)."""
    if "in" not in relations:
        return top
    high = top + ABOVE_TOP if "on" in relations else top
    return (top / 2.0 + high) / 2.0


def support_cones(mind: Mind, support: KnownObject, p_total: float, camera: CameraModel,
                  key: str, distances: tuple[float, ...] = (0.9, 1.2, 1.5),
                  max_cones: int = 4, relations: tuple[str, ...] = ("on",)) -> ConeSet:
    """Views around a known support from traversable standpoints, facing its top (inside
    it, or between, by `relations`: `support_relations`); the nearest standpoint per
    direction, then the most spread-out directions."""
    sx, sy = support.position[:2]
    top = max(0.3, min(aim_height(2.0 * support.position[2], relations), camera.height - 0.1))
    free = mind.grid.traversable(mind.config.robot_radius)
    stands = []
    for k in range(12):
        angle = k * math.pi / 6
        for distance in distances:
            x, y = sx + distance * math.cos(angle), sy + distance * math.sin(angle)
            cell = mind.grid.cell_of((x, y))
            if mind.grid.contains(cell) and free[cell]:
                tilt = -math.atan2(camera.height - top, distance)
                stands.append((x, y, math.atan2(sy - y, sx - x), tilt))
                break
    picked = stands[:: max(1, math.ceil(len(stands) / max_cones))][:max_cones]
    share = p_total / len(picked) if picked else 0.0
    cones = tuple(ViewCone(f"{key}-{i}", (x, y, yaw), share, head=(0.0, tilt))
                  for i, (x, y, yaw, tilt) in enumerate(picked))
    return ConeSet(cones, 0.9 if picked else 0.0, p_total)


def standpoints(mind: Mind, room: str, spacing: float = 1.0) -> list[tuple[float, float]]:
    """Where a room's views may stand: its places, then the points of its free floor
    (`PlaceMap.room_extents`) on a `spacing` lattice where the robot's body fits. The far
    side of a room the robot has only looked into from one end is seen from there; the DT
    leaves out a view no path reaches."""
    pm, grid = mind.place_map, mind.grid
    places = [pm.places[p].position for p in sorted(pm.rooms[room].places) if p in pm.places]
    owner, ids = pm.room_extents(grid)
    if room not in ids:
        return places
    step = max(1, round(spacing / grid.resolution))
    lattice = np.zeros(owner.shape, dtype=bool)
    lattice[::step, ::step] = True
    floor = (owner == ids.index(room) + 1) & lattice & grid.traversable(mind.config.robot_radius)
    extra = grid.to_world(np.argwhere(floor))
    return places + [(float(x), float(y)) for x, y in extra]


def _room_cells(mind: Mind, room: str) -> np.ndarray:
    """World centres of the occupied/unknown cells bordering this room's free floor."""
    points, rooms = candidate_cells(mind)
    return points[rooms == room][::2]


def candidate_cells(mind: Mind) -> tuple[np.ndarray, np.ndarray]:
    """Where objects (and their supports) may be: the centres of occupied/unknown cells next
    to free space, each with the room whose free floor it borders (`PlaceMap.room_extents`:
    the free space, split at the doors, that the room's places stand in), however far from
    the places (an object array of room ids). A cell bordering two rooms' floors (a thin
    wall) is listed for each; one bordering only free space no room holds (a room seen
    through a door but not entered) is not listed: a look at it is no evidence about the
    rooms the robot has been in. Cached until the grid or the rooms change."""
    grid, pm = mind.grid, mind.place_map
    if not pm.rooms:
        return np.zeros((0, 2)), np.zeros(0, dtype=object)
    owner, ids = pm.room_extents(grid)
    key = (id(grid), grid.version, id(owner), tuple(ids))
    if mind.cell_cache is not None and mind.cell_cache[0] == key:
        return mind.cell_cache[1]
    edge = grid.state_grid() != CellState.FREE
    padded = np.pad(owner, 1)  # the owner of each cell's neighbour below, above, right, left
    found = []
    for beside in (padded[2:, 1:-1], padded[:-2, 1:-1], padded[1:-1, 2:], padded[1:-1, :-2]):
        mask = edge & (beside > 0)
        found.append(np.column_stack([np.argwhere(mask), beside[mask]]))
    rows = np.unique(np.concatenate(found), axis=0)
    names = np.array(ids, dtype=object)
    result = (grid.to_world(rows[:, :2]), names[rows[:, 2] - 1])
    mind.cell_cache = (key, result)
    return result


def _in_wedge(points: np.ndarray, pose: tuple[float, float, float],
              camera: CameraModel) -> np.ndarray:
    d = points - np.asarray(pose[:2])
    r = np.hypot(d[:, 0], d[:, 1])
    bearing = np.abs((np.arctan2(d[:, 1], d[:, 0]) - pose[2] + np.pi) % (2 * np.pi) - np.pi)
    return (r <= 0.9 * camera.detect_range) & (r >= 0.5) & (bearing <= camera.hfov / 2)
