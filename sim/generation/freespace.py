"""Where a robot base fits inside one room: a 10 cm grid of cells the larger footprint clears.

Used while furnishing (a piece that would cut a room's doors apart, or leave a piece of
furniture out of reach, is not placed) and to pick the robot's start.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sim.generation.layout import DoorPlan, Rect

CELL = 0.1
FOOTPRINT = 0.34  # the larger robot (pr2); the pioneer's is 0.26
WALL_HALF = 0.05  # half the default wall thickness
OBSTACLE_CLEARANCE = FOOTPRINT + 0.02  # cell centre to furniture
WALL_CLEARANCE = FOOTPRINT + WALL_HALF + 0.03  # cell centre to a room border
APPROACH = 0.55  # metres inside a room in front of a door: where the robot stands to pass it
REACH = FOOTPRINT + 0.6  # a furniture piece is in reach from a cell this close to it


@dataclass(frozen=True)
class FreeSpace:
    """The free cells of a room and their 4-connected components (label 0 is blocked)."""

    rect: Rect
    labels: np.ndarray  # (ny, nx) component label per cell

    def cell_centre(self, iy: int, ix: int) -> tuple[float, float]:
        return (self.rect[0] + (ix + 0.5) * CELL, self.rect[1] + (iy + 0.5) * CELL)

    def label_at(self, x: float, y: float) -> int:
        ix = int((x - self.rect[0]) / CELL)
        iy = int((y - self.rect[1]) / CELL)
        ny, nx = self.labels.shape
        return int(self.labels[iy, ix]) if 0 <= ix < nx and 0 <= iy < ny else 0

    def cells_of(self, label: int) -> list[tuple[float, float]]:
        """Centres of the cells of one component."""
        iys, ixs = np.nonzero(self.labels == label)
        return [self.cell_centre(int(iy), int(ix)) for iy, ix in zip(iys, ixs, strict=True)]


def free_space(rect: Rect, obstacles: list[Rect]) -> FreeSpace:
    """Cells of `rect` whose centre clears the walls and every obstacle rectangle."""
    x0, y0, x1, y1 = rect
    xs = x0 + (np.arange(max(1, round((x1 - x0) / CELL))) + 0.5) * CELL
    ys = y0 + (np.arange(max(1, round((y1 - y0) / CELL))) + 0.5) * CELL
    gx, gy = np.meshgrid(xs, ys)
    free = ((gx - x0 >= WALL_CLEARANCE) & (x1 - gx >= WALL_CLEARANCE)
            & (gy - y0 >= WALL_CLEARANCE) & (y1 - gy >= WALL_CLEARANCE))
    for box in obstacles:
        free &= _distance(gx, gy, box) >= OBSTACLE_CLEARANCE
    labels, _ = ndimage.label(free)
    return FreeSpace(rect, labels)


def _distance(gx: np.ndarray, gy: np.ndarray, box: Rect) -> np.ndarray:
    dx = np.maximum(np.maximum(box[0] - gx, 0.0), gx - box[2])
    dy = np.maximum(np.maximum(box[1] - gy, 0.0), gy - box[3])
    return np.hypot(dx, dy)


def approach_point(rect: Rect, door: DoorPlan) -> tuple[float, float]:
    """The point APPROACH metres inside `rect` straight in front of `door`."""
    x, y = door.at
    if door.axis == "x":
        return (x + APPROACH if abs(x - rect[0]) < 1e-6 else x - APPROACH, y)
    return (x, y + APPROACH if abs(y - rect[1]) < 1e-6 else y - APPROACH)


def door_zone(rect: Rect, door: DoorPlan, depth: float = 1.0, side: float = 0.15) -> Rect:
    """The strip inside `rect` in front of `door` that furniture must leave free."""
    x, y = door.at
    half = door.width / 2 + side
    if door.axis == "x":
        inward = abs(x - rect[0]) < 1e-6
        return (x, y - half, x + depth, y + half) if inward else (x - depth, y - half, x, y + half)
    inward = abs(y - rect[1]) < 1e-6
    return (x - half, y, x + half, y + depth) if inward else (x - half, y - depth, x + half, y)


def passable(space: FreeSpace, entries: list[tuple[float, float]],
             reach: list[Rect]) -> bool:
    """All `entries` lie in one free component, and each `reach` box is near a cell of it."""
    labels = {space.label_at(x, y) for x, y in entries}
    if len(labels) != 1 or 0 in labels:
        return False
    (label,) = labels
    mask = space.labels == label
    ny, nx = mask.shape
    xs = space.rect[0] + (np.arange(nx) + 0.5) * CELL
    ys = space.rect[1] + (np.arange(ny) + 0.5) * CELL
    gx, gy = np.meshgrid(xs, ys)
    return all(bool(np.any(mask & (_distance(gx, gy, box) <= REACH))) for box in reach)
