"""QSR view selection (Kunze et al., eq. 2 and Algorithm 1): where to stand and where to look."""

from avs_planner.qsr.geometry import in_frustums, in_view_cones, line_of_sight
from avs_planner.qsr.landmarks import OPEN_SIDE_RADIUS, LandmarkTracker, landmarks_from, open_side
from avs_planner.qsr.poses import candidate_cells, reachable, sample_poses
from avs_planner.qsr.select import (
    Frustum,
    ScoredPose,
    SelectionStatus,
    ViewMethod,
    ViewOptions,
    ViewSelection,
    ViewSelectionError,
    best_rate,
    cone_half_angle,
    pose_rates,
    pose_times,
    rank_frustums,
    score_cones,
    score_poses,
    select_view,
)

__all__ = [
    "OPEN_SIDE_RADIUS",
    "LandmarkTracker",
    "landmarks_from",
    "open_side",
    "Frustum",
    "ScoredPose",
    "SelectionStatus",
    "ViewMethod",
    "ViewOptions",
    "ViewSelection",
    "ViewSelectionError",
    "best_rate",
    "candidate_cells",
    "cone_half_angle",
    "in_frustums",
    "in_view_cones",
    "line_of_sight",
    "pose_rates",
    "pose_times",
    "rank_frustums",
    "reachable",
    "sample_poses",
    "score_cones",
    "score_poses",
    "select_view",
]
