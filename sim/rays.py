"""Batched ray casting against the static world (the robot itself is never hit)."""

from __future__ import annotations

import numpy as np
from pybullet_utils.bullet_client import BulletClient

from sim.scene import WORLD_GROUP

_BATCH = 8192  # below pybullet's per-call ray limit


def cast_rays(client: BulletClient, starts: np.ndarray,
              ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cast rays start→end; returns (hit fraction in [0, 1] or 1.0 on a miss, hit body or -1)."""
    fractions = np.ones(len(starts))
    bodies = np.full(len(starts), -1, dtype=int)
    for lo in range(0, len(starts), _BATCH):
        hits = client.rayTestBatch(starts[lo:lo + _BATCH].tolist(), ends[lo:lo + _BATCH].tolist(),
                                   collisionFilterMask=WORLD_GROUP)
        for k, hit in enumerate(hits):
            bodies[lo + k] = hit[0]
            fractions[lo + k] = hit[2] if hit[0] >= 0 else 1.0
    return fractions, bodies


def ranges_along(client: BulletClient, origin: np.ndarray, directions: np.ndarray,
                 max_range: float) -> np.ndarray:
    """Distance to the first world surface along each unit direction (np.inf beyond max_range)."""
    starts = np.broadcast_to(origin, directions.shape)
    fractions, bodies = cast_rays(client, starts, starts + directions * max_range)
    return np.where(bodies >= 0, fractions * max_range, np.inf)
