"""The robot's picture of the building, scored against the world file at the end of an episode.

This is the harness's referee, not part of the robot's mind: the episode wiring
(`runner.Episode.summary`) calls it once the search is over, with the world spec's true rooms
and the mind's place map, and the score goes into `summary.json` as `map_score`. Nothing the
robot decides reads it.

The robot's rooms are the place map's rooms with the known free cells they hold
(`PlaceMap.room_extents`: the free space, split at the doors, that a room's places stand in).
Each true room (a rectangle of the world file) is compared on the free cells the robot mapped
inside it, so a room mapped whole and segmented right scores IoU 1 however much furniture or
unseen floor it has:

- **segmentation**: a true room is *matched* when one robot room overlaps it at IoU >= 0.5
  (one-to-one, best IoU first); a *merge* is a robot room that substantially overlaps two or
  more true rooms (a door not recognised); a *split* is a true room substantially overlapped
  by two or more robot rooms (a door seen where there is none). Substantially: at least
  `SUBSTANTIAL_M2` and `SUBSTANTIAL_SHARE` of the smaller of the two.
  A search that ends early leaves rooms unseen, and those cannot be matched: the score
  also counts the true rooms matched among those the robot entered (`entered_matched` of
  `entered_rooms`), the segmentation of what it did see.
- **categories**: over the true rooms the robot entered (its path passed at least
  `ENTER_DEPTH` inside), the most probable category the robot believes for the robot room
  covering most of the true room, against the world file's category, weighted by the true
  room's floor area. A merged room is judged by the one belief it has.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from conceptual_map.metric import CellState

MATCH_IOU = 0.5  # a true room is matched by a robot room at least this IoU
SUBSTANTIAL_M2 = 1.0  # m^2: an overlap smaller than this never counts for a merge or split
SUBSTANTIAL_SHARE = 0.2  # ... nor one below this share of the smaller of the two
ENTER_DEPTH = 0.3  # m: a true room is entered when the path went this far inside it
PATH_STEP = 0.1  # m: the path is checked at points this far apart

Rect = tuple[float, float, float, float]


@dataclass(frozen=True)
class TrueRoom:
    """A room of the world file: name, category, rectangle (x0, y0, x1, y1)."""

    name: str
    category: str
    rect: Rect

    @property
    def area(self) -> float:
        x0, y0, x1, y1 = self.rect
        return (x1 - x0) * (y1 - y0)

    def holds(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        x0, y0, x1, y1 = self.rect
        return ((points[:, 0] >= x0 + margin) & (points[:, 0] <= x1 - margin)
                & (points[:, 1] >= y0 + margin) & (points[:, 1] <= y1 - margin))


@dataclass(frozen=True)
class RobotMap:
    """The robot's rooms as cells: the centres (N, 2) of the known free cells, each cell's
    robot room (None: no room holds it), the area of one cell, and each robot room's
    category belief."""

    cells: np.ndarray
    owner: Sequence[str | None]
    cell_area: float
    beliefs: Mapping[str, Mapping[str, float]]


def normalise(category: str) -> str:
    """One spelling per category (as the world files': case, spaces, hyphens)."""
    return "_".join(category.strip().lower().replace("-", " ").split())


def score_map(truth: Sequence[TrueRoom], robot: RobotMap,
              path: Sequence[Sequence[float]]) -> dict[str, Any]:
    """The score of `robot`'s rooms against the true rooms (see the module docstring)."""
    cells = np.asarray(robot.cells, dtype=float).reshape(-1, 2)
    owner = np.asarray(list(robot.owner), dtype=object)
    rids = sorted({o for o in owner.tolist() if o is not None} | set(robot.beliefs))
    area = robot.cell_area
    inside = np.array([t.holds(cells) for t in truth]).reshape(len(truth), len(cells))
    mine = np.array([owner == r for r in rids], dtype=bool).reshape(len(rids), len(cells))
    # overlap[i, j]: m^2 of true room i that robot room j holds; known[i]: m^2 mapped free
    overlap = (inside.astype(float) @ mine.T.astype(float)) * area
    known = inside.sum(axis=1) * area
    size = mine.sum(axis=1) * area
    union = known[:, None] + size[None, :] - overlap
    iou = np.divide(overlap, union, out=np.zeros_like(overlap), where=union > 0)
    matched = _match(iou)
    substantial = (overlap >= SUBSTANTIAL_M2) & (
        overlap >= SUBSTANTIAL_SHARE * np.minimum(known[:, None], size[None, :]))
    entered = _entered(truth, path)
    rooms, right, entered_area = [], 0.0, 0.0
    for i, room in enumerate(truth):
        j = matched.get(i)
        if j is None and len(rids) and overlap[i].max() > 0:
            j_best = int(overlap[i].argmax())
        else:
            j_best = j
        rid = rids[j_best] if j_best is not None else None
        believed, p = _top(robot.beliefs.get(rid) if rid is not None else None)
        correct = believed is not None and normalise(believed) == normalise(room.category)
        if entered[i]:
            entered_area += room.area
            right += room.area if correct else 0.0
        rooms.append({
            "name": room.name, "category": room.category, "area_m2": round(room.area, 2),
            "mapped_m2": round(float(known[i]), 2), "entered": bool(entered[i]),
            "robot_room": rid, "matched": j is not None,
            "iou": round(float(iou[i, j_best]), 3) if j_best is not None else 0.0,
            "believed": believed, "p": p,
        })
    return {
        "rooms_true": len(truth), "rooms_robot": len(rids), "rooms_matched": len(matched),
        "merges": int(np.count_nonzero(substantial.sum(axis=0) >= 2)),
        "splits": int(np.count_nonzero(substantial.sum(axis=1) >= 2)),
        "entered_rooms": int(sum(entered)),
        "entered_matched": sum(1 for i in matched if entered[i]),
        "entered_area_m2": round(entered_area, 2),
        "category_accuracy": round(right / entered_area, 4) if entered_area > 0 else None,
        "rooms": rooms,
    }


def _match(iou: np.ndarray) -> dict[int, int]:
    """True room -> robot room, one-to-one, best IoU first, only pairs at IoU >= MATCH_IOU."""
    pairs = sorted(((float(iou[i, j]), i, j) for i, j in zip(*np.nonzero(iou >= MATCH_IOU),
                                                             strict=True)), reverse=True)
    out: dict[int, int] = {}
    used: set[int] = set()
    for _, i, j in pairs:
        if i not in out and j not in used:
            out[int(i)] = int(j)
            used.add(int(j))
    return out


def _entered(truth: Sequence[TrueRoom], path: Sequence[Sequence[float]]) -> list[bool]:
    """Whether the path (its points joined by straight legs) went `ENTER_DEPTH` into each."""
    points = np.asarray([p[:2] for p in path], dtype=float).reshape(-1, 2)
    if len(points) > 1:
        legs = [points[:1]]
        for a, b in zip(points[:-1], points[1:], strict=True):
            n = max(1, math.ceil(float(np.linalg.norm(b - a)) / PATH_STEP))
            t = np.linspace(0.0, 1.0, n + 1)[1:, None]
            legs.append(a * (1 - t) + b * t)
        points = np.vstack(legs)
    return [bool(room.holds(points, ENTER_DEPTH).any()) for room in truth]


def _top(belief: Mapping[str, float] | None) -> tuple[str | None, float | None]:
    if not belief:
        return None, None
    category, p = max(belief.items(), key=lambda kv: kv[1])
    return category, round(float(p), 4)


# ---- reading the world file and the mind (the harness's side) ---------------------------------


def true_rooms(world: Any) -> list[TrueRoom]:
    """The world spec's rooms (anything with `rooms` of `name`, `category`, `rect`)."""
    return [TrueRoom(r.name, r.category, tuple(float(v) for v in r.rect)) for r in world.rooms]


def robot_map(mind: Any) -> RobotMap | None:
    """The mind's rooms as cells with their category beliefs; None before any room exists."""
    pm, grid = mind.place_map, mind.grid
    if not pm.rooms:
        return None
    owner_grid, ids = pm.room_extents(grid)
    free = np.argwhere(grid.state_grid() == CellState.FREE)
    cells = grid.to_world(free)
    names = np.asarray([None, *ids], dtype=object)
    owner = names[owner_grid[free[:, 0], free[:, 1]]]
    beliefs = {rid: mind.cmap.room_category(rid) for rid in ids
               if mind.cmap.graph.has_room(rid)}
    return RobotMap(cells, owner.tolist(), grid.resolution ** 2, beliefs)


def map_score(world: Any, mind: Any, path: Sequence[Sequence[float]]) -> dict[str, Any] | None:
    """`score_map` of the mind's place map against the world's rooms, with the robot's path
    (x, y, ...) for which rooms it entered; None when the mind has no rooms."""
    robot = robot_map(mind)
    if robot is None:
        return None
    return score_map(true_rooms(world), robot, path)


SUPPORT_REACH = 0.8  # m: a known object this near an instance (in the plane) may hold it


def evidence_score(instances: Sequence[tuple[str, Sequence[float], str | None]], mind: Any,
                   label: str, detected: set[str], reported: set[str]) -> list[dict[str, Any]]:
    """How the robot's looks judged the places the target's true instances stand in, against
    whether the camera ever saw them: for each instance (name, centre, the robot room that
    `score_map` matched to its true room, or None), the share of `label`s in that room the
    mind's looks claim they would have seen (1 - the ledger's `remaining`: searches and
    frames in passing), the same for the spaces on and in known objects within
    `SUPPORT_REACH` m (the largest), whether any frame detected it (`detected`: the world
    entries detections were made of) and whether it was reported. A claim of 0.9 over
    instances no frame ever detected says the looks are credited with more than they saw.
    Scoring only: nothing the robot decides reads it."""
    from conceptual_map.conceptual.existence import RelatedSpace

    ledger = mind.cmap.objects
    out: list[dict[str, Any]] = []
    for name, centre, room in instances:
        known = room is not None and mind.cmap.graph.has_room(room)
        claim_room = 1.0 - ledger.remaining(room, label) if known else 0.0
        claim_space = 0.0
        for obj in mind.objects.values():
            if obj.label == label or math.dist(obj.position[:2], centre[:2]) > SUPPORT_REACH:
                continue
            for relation in ("on", "in"):
                space = RelatedSpace(relation, obj.id)
                claim_space = max(claim_space, 1.0 - ledger.remaining(space, label))
        out.append({"name": name, "room": room if known else None,
                    "claimed_room": round(claim_room, 4), "claimed_support": round(claim_space, 4),
                    "detected": name in detected, "reported": name in reported})
    return out
