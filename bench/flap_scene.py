"""A synthetic room with tables, clutter and a shelf for the FLAP tests and benchmark.

The maps are built the way the robot would build them: laser scans and depth frames ray-cast
from a few poses into an OccupancyGrid and a VoxelMap; the target volumes are then reset to
unknown (the FLAP paper's "maps that get out of date"). No simulator is involved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from avs_planner.body import JointRange, RobotBody
from avs_planner.flap.target import TargetVolume
from conceptual_map.metric import OccupancyGrid, VoxelMap
from conceptual_map.metric.synthetic import BoxWorld, rooms_world

PR2_BODY = RobotBody(
    name="pr2", footprint_radius=0.34, holonomic=True, camera_height=1.2,
    torso=JointRange(0.0, 0.31), pan=JointRange(math.radians(-175), math.radians(175)),
    tilt=JointRange(math.radians(-60), math.radians(55)), hfov=math.radians(58),
    vfov=math.radians(45), depth_range=4.5, detect_range=3.5, laser_range=10.0,
    linear_speed=0.5, angular_speed=0.8, torso_speed=0.015, pan_speed=2.0, tilt_speed=2.0,
    scan_time=0.1, sensing_time=1.0,
)  # fmt: skip
PIONEER_BODY = RobotBody(
    name="pioneer", footprint_radius=0.26, holonomic=False, camera_height=1.4,
    torso=JointRange(0.0, 0.0), pan=JointRange(math.radians(-159), math.radians(159)),
    tilt=JointRange(math.radians(-47), math.radians(31)), hfov=math.radians(60),
    vfov=math.radians(45), depth_range=5.0, detect_range=4.0, laser_range=5.6,
    linear_speed=0.5, angular_speed=1.0, torso_speed=1.0, pan_speed=1.0, tilt_speed=1.0,
    scan_time=0.1, sensing_time=0.5,
)  # fmt: skip


@dataclass
class Scene:
    """A world of boxes, the robot's maps of it, the target volumes and a start pose."""

    world: BoxWorld
    voxels: VoxelMap
    grid: OccupancyGrid
    volumes: list[TargetVolume]
    start: tuple[float, float, float]


def room_world(size: tuple[float, float] = (6.0, 5.0)) -> tuple[BoxWorld, list[TargetVolume]]:
    """One room with two cluttered tables and a two-level shelf; volumes over their tops."""
    w, h = size
    world = rooms_world([(0.0, 0.0, w, h)], [])
    tables = [(1.2, 1.0, 2.4, 1.8), (3.6, 3.0, 4.6, 3.8)]
    volumes = []
    for k, (x0, y0, x1, y1) in enumerate(tables):
        world.add_box(x0, y0, x1, y1, 0.0, 0.75)
        world.add_box(x0 + 0.2, y0 + 0.2, x0 + 0.45, y0 + 0.35, 0.75, 0.97)  # clutter
        world.add_box(x1 - 0.4, y1 - 0.3, x1 - 0.25, y1 - 0.12, 0.75, 1.0)
        volumes.append(TargetVolume((x0, y0, 0.75), (x1, y1, 1.05), 0.2, f"table{k}"))
    shelf = (w - 0.5, 0.8, w - 0.06, 2.0)
    for z in (0.0, 0.6):
        world.add_box(shelf[0], shelf[1], shelf[2], shelf[3], z, z + 0.05)
    world.add_box(shelf[0], shelf[1], shelf[2], shelf[3], 1.2, 1.25)
    for z0 in (0.05, 0.65):
        volumes.append(TargetVolume((shelf[0], shelf[1], z0), (shelf[2], shelf[3], z0 + 0.5),
                                    0.2, f"shelf{z0:.2f}"))
    return world, volumes


def build_scene(
    size: tuple[float, float] = (6.0, 5.0), resolution: float = 0.05, reset: bool = True
) -> Scene:
    """Map the room from three poses (laser + a ring of depth frames), then reset the volumes."""
    world, volumes = room_world(size)
    w, h = size
    voxels = VoxelMap(origin=(-0.3, -0.3, 0.0), size=(w + 0.6, h + 0.6, 2.0),
                      resolution=resolution)
    grid = OccupancyGrid(origin=(-0.3, -0.3), size=(w + 0.6, h + 0.6), resolution=resolution)
    stops = [(0.8 * w, 0.25 * h), (0.25 * w, 0.75 * h), (0.5 * w, 0.5 * h)]
    for x, y in stops:
        grid.integrate_scan(world.laser((x, y, 0.0), beams=720, max_range=8.0))
        for yaw in np.linspace(-math.pi, math.pi, 8, endpoint=False):
            for pitch in (-0.6, 0.0):
                voxels.integrate_depth(world.depth((x, y, 1.3), yaw, pitch, size=(48, 36),
                                                   max_range=4.5))
    if reset:
        for volume in volumes:
            voxels.reset_box(volume.lo, volume.hi)
    return Scene(world, voxels, grid, volumes, (stops[-1][0], stops[-1][1], 0.0))
