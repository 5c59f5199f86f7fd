"""The desk scene of the QSR paper's experiments (`sim/worlds/qsr_desks.yaml`) as synthetic maps.

For QSR tests and benchmarks only: the geometry is written out here (nothing imports `sim`), and
the maps are filled as if fully observed (boxes occupied, air free), so supporting planes and
view selection can be checked against the desks' known tops.
"""

from __future__ import annotations

import math

import numpy as np

from conceptual_map.metric import OccupancyGrid, VoxelMap
from conceptual_map.qsr import Landmark, QsrKnowledge

SIZE = (8.0, 6.0)
WALL_HEIGHT = 2.0
# name, x, y, yaw, length, depth, height (the desks of qsr_desks.yaml)
DESKS = [("desk1", 1.5, 5.5, 0.0, 1.6, 0.8, 0.74), ("desk2", 4.0, 5.5, 0.0, 1.6, 0.8, 0.74),
         ("desk3", 6.5, 5.5, 0.0, 1.6, 0.8, 0.74),
         ("desk4", 7.5, 3.0, -math.pi / 2, 1.6, 0.8, 0.74)]  # fmt: skip
# name, label, desk index, dx, dy (in the desk's frame), size x, y, z
OBJECTS = [("monitor1", "monitor", 0, 0.0, 0.2, 0.5, 0.15, 0.4),
           ("keyboard1", "keyboard", 0, 0.0, -0.15, 0.45, 0.15, 0.03),
           ("cup1", "cup", 0, 0.4, -0.15, 0.08, 0.08, 0.1),
           ("monitor2", "monitor", 1, 0.0, 0.2, 0.5, 0.15, 0.4),
           ("keyboard2", "keyboard", 1, 0.0, -0.15, 0.45, 0.15, 0.03),
           ("laptop2", "laptop", 1, -0.55, -0.1, 0.33, 0.23, 0.03),
           ("monitor3", "monitor", 2, 0.0, 0.2, 0.5, 0.15, 0.4),
           ("keyboard3", "keyboard", 2, 0.0, -0.15, 0.45, 0.15, 0.03),
           ("cup3", "cup", 2, -0.4, -0.15, 0.08, 0.08, 0.1),
           ("bottle3", "bottle", 2, -0.4, 0.05, 0.07, 0.07, 0.25),
           ("monitor4", "monitor", 3, 0.0, 0.2, 0.5, 0.15, 0.4),
           ("keyboard4", "keyboard", 3, 0.0, -0.15, 0.45, 0.15, 0.03)]  # fmt: skip
# interior walls: the corridor/lab wall at y = 1.5 with a door 3.55..4.45
WALLS = [(0.0, 1.45, 3.55, 1.55), (4.45, 1.45, 8.0, 1.55)]


def _rotate(yaw: float, dx: float, dy: float) -> tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * dx - s * dy, s * dx + c * dy


def _footprint(x: float, y: float, yaw: float, sx: float, sy: float) -> tuple[float, ...]:
    """Axis-aligned (x0, y0, x1, y1) of a box turned by a multiple of 90 degrees."""
    quarter = round(yaw / (math.pi / 2))
    assert abs(yaw - quarter * math.pi / 2) < 1e-6, "only right-angle yaws are supported"
    hx, hy = (sx / 2, sy / 2) if quarter % 2 == 0 else (sy / 2, sx / 2)
    return (x - hx, y - hy, x + hx, y + hy)


def desk_tops() -> dict[str, tuple[float, float, float, float, float]]:
    """Desk name -> (x0, y0, x1, y1, height) of its top."""
    return {n: (*_footprint(x, y, yaw, sx, sy), h) for n, x, y, yaw, sx, sy, h in DESKS}


def object_poses() -> dict[str, tuple[str, float, float, float, float]]:
    """Object name -> (label, x, y, z_bottom, yaw) as the world file places it."""
    out = {}
    for name, label, desk, dx, dy, *_ in OBJECTS:
        _, x, y, yaw, _, _, h = DESKS[desk]
        ox, oy = _rotate(yaw, dx, dy)
        out[name] = (label, x + ox, y + oy, h, yaw)
    return out


def boxes(skip: tuple[str, ...] = ()) -> list[tuple[float, float, float, float, float, float]]:
    """Every solid as (x0, y0, z0, x1, y1, z1): desks, things on them (but those named in
    `skip`), walls."""
    out = [(*top[:2], 0.0, *top[2:4], top[4]) for top in desk_tops().values()]
    poses = object_poses()
    for name, _, _, _, _, sx, sy, sz in OBJECTS:
        if name in skip:
            continue
        _, x, y, z, yaw = poses[name]
        x0, y0, x1, y1 = _footprint(x, y, yaw, sx, sy)
        out.append((x0, y0, z, x1, y1, z + sz))
    out += [(x0, y0, 0.0, x1, y1, WALL_HEIGHT) for x0, y0, x1, y1 in WALLS]
    return out


def voxel_map(resolution: float = 0.05, skip: tuple[str, ...] = ()) -> VoxelMap:
    """The room as a fully observed voxel map (objects named in `skip` left out)."""
    voxels = VoxelMap((0.0, 0.0, 0.0), (*SIZE, WALL_HEIGHT), resolution)
    fill_voxels(voxels, boxes(skip))
    return voxels


def fill_voxels(voxels: VoxelMap, solids: list[tuple[float, ...]]) -> None:
    """Cells a box overlaps become occupied, every other cell free."""
    m = voxels.model
    voxels.logodds[...] = m.clamp_min
    res, origin, shape = voxels.resolution, voxels.origin, np.asarray(voxels.shape)
    for box in solids:
        lo = np.floor((np.asarray(box[:3]) - origin) / res + 1e-9).astype(int)
        hi = np.ceil((np.asarray(box[3:]) - origin) / res - 1e-9).astype(int)
        lo, hi = np.clip(lo, 0, shape), np.clip(hi, 0, shape)
        voxels.logodds[lo[0] : hi[0], lo[1] : hi[1], lo[2] : hi[2]] = m.clamp_max


def occupancy_grid(resolution: float = 0.05) -> OccupancyGrid:
    """The floor plan: desks, interior walls and the outer border occupied, the rest free."""
    grid = OccupancyGrid((0.0, 0.0), SIZE, resolution)
    m = grid.model
    grid.logodds[...] = m.clamp_min
    grid.logodds[[0, -1], :] = m.clamp_max
    grid.logodds[:, [0, -1]] = m.clamp_max
    for x0, y0, _, x1, y1, _ in boxes():
        lo = np.floor(np.array([x0, y0]) / resolution + 1e-9).astype(int)
        hi = np.ceil(np.array([x1, y1]) / resolution - 1e-9).astype(int)
        grid.logodds[lo[0] : hi[0], lo[1] : hi[1]] = m.clamp_max
    grid._touch()  # the cached states must see the direct write
    return grid


def landmarks(knowledge: QsrKnowledge, labels: tuple[str, ...] = ("monitor", "keyboard", "desk")
              ) -> list[Landmark]:  # fmt: skip
    """Landmarks (with their known poses) of the given labels."""
    out = [knowledge.landmark(label, x, y, yaw, name)
           for name, (label, x, y, _, yaw) in object_poses().items() if label in labels]
    if "desk" in labels:
        out += [knowledge.landmark("desk", x, y, yaw, name) for name, x, y, yaw, *_ in DESKS]
    return out
