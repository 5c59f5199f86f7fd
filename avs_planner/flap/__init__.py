"""FLAP view planning (Gedicke et al.): frontier-based view sampling in the 3D voxel map, target
probability per cell (eq. 1-3), transition times, and expected-time sequencing (eq. 4-9).

Gedicke, Günther and Hertzberg, "FLAP for CAOS: Forward-Looking Active Perception for
Clutter-Aware Object Search". The modules are described in README.md beside this file.
"""

from avs_planner.flap.errors import FlapError
from avs_planner.flap.planner import (
    EXACT,
    GREEDY,
    PlannerOptions,
    PlanResult,
    StopReason,
    plan_exhaustive,
    plan_greedy,
    plan_views,
)
from avs_planner.flap.problem import SequencingProblem
from avs_planner.flap.sampling import SamplerOptions, View, ViewPose, ViewSampler
from avs_planner.flap.search import Decision, FlapOptions, FlapSearch, SearchStatus
from avs_planner.flap.target import TargetBelief, TargetVolume, uniform_volumes
from avs_planner.flap.transitions import TransitionTable, build_table, exact_time

__all__ = [
    "EXACT",
    "GREEDY",
    "Decision",
    "FlapError",
    "FlapOptions",
    "FlapSearch",
    "PlanResult",
    "PlannerOptions",
    "SamplerOptions",
    "SearchStatus",
    "SequencingProblem",
    "StopReason",
    "TargetBelief",
    "TargetVolume",
    "TransitionTable",
    "View",
    "ViewPose",
    "ViewSampler",
    "build_table",
    "exact_time",
    "plan_exhaustive",
    "plan_greedy",
    "plan_views",
    "uniform_volumes",
]
