"""The simulated planar laser: ray tests in a fan at the sensor height, Gaussian range noise."""

from __future__ import annotations

import numpy as np
from pybullet_utils.bullet_client import BulletClient

from sim.rays import ranges_along
from sim.robot_models import LaserSpec
from sim.sensor_data import LaserScan


def laser_scan(client: BulletClient, pose: tuple[float, float, float], height: float,
               spec: LaserSpec, rng: np.random.Generator, time: float) -> LaserScan:
    """One scan from sensor pose (x, y, yaw) at `height`; misses are np.inf, hits are noisy."""
    x, y, yaw = pose
    angles = np.linspace(-spec.fov / 2, spec.fov / 2, spec.beams)
    world = angles + yaw
    directions = np.column_stack([np.cos(world), np.sin(world), np.zeros_like(world)])
    ranges = ranges_along(client, np.array([x, y, height]), directions, spec.max_range)
    hit = np.isfinite(ranges)
    noisy = ranges[hit] + rng.normal(0.0, spec.noise_sigma, hit.sum())
    ranges[hit] = np.clip(noisy, 0.0, spec.max_range)
    return LaserScan(pose=(x, y, yaw), angles=angles, ranges=ranges, max_range=spec.max_range,
                     height=height, time=time)
