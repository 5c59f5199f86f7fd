"""Metric layer: 2D occupancy grid with A* paths, 3D voxel map with frontiers."""

from conceptual_map.metric.errors import PathQueryError, SensorDataError
from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.logodds import CellState, SensorModel, UpdateSummary
from conceptual_map.metric.path_planning import (
    PathResult,
    PathStatus,
    distance_field,
    distance_fields,
    distances_at,
    plan_path,
)
from conceptual_map.metric.sensors import DepthFrameLike, LaserScanLike, Rays
from conceptual_map.metric.voxels import VoxelMap

__all__ = [
    "CellState",
    "DepthFrameLike",
    "LaserScanLike",
    "OccupancyGrid",
    "PathQueryError",
    "PathResult",
    "PathStatus",
    "Rays",
    "SensorDataError",
    "SensorModel",
    "UpdateSummary",
    "VoxelMap",
    "distance_field",
    "distance_fields",
    "distances_at",
    "plan_path",
]
