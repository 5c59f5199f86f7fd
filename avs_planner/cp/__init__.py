"""The continual planner (CP) of Göbelbecker et al., "A Planning Approach to Active Visual Search
in Large Environments": plans minimising c(pi) + R(1 - p(pi)).

Parse -> `ground` (bitsets, cached per domain/objects/static atoms) -> `search` (weighted A*,
heuristics by name from `HEURISTICS`). `plan` does both; `ContinualPlanner` adds monitoring,
virtual-object matching, replanning and giving up for the switching loop. The UP engine
"avs" lives in `avs_planner.up_engine` (import it to register).
"""

from avs_planner.cp.continual import ContinualPlanner, Decision, Update
from avs_planner.cp.grounding import GroundingCache, ground, world_state
from avs_planner.cp.heuristics import HEURISTICS, get_heuristic
from avs_planner.cp.matching import match_virtual_objects, rename_plan
from avs_planner.cp.monitor import MonitorReport, MonitorStatus, monitor
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanResult, PlanStatus, PlanStep, SearchOptions, search
from avs_planner.cp.task import GroundAction, GroundTask, WorldState

__all__ = [
    "HEURISTICS",
    "ContinualPlanner",
    "Decision",
    "GroundAction",
    "GroundTask",
    "GroundingCache",
    "MonitorReport",
    "MonitorStatus",
    "PlanResult",
    "PlanStatus",
    "PlanStep",
    "SearchOptions",
    "Update",
    "WorldState",
    "get_heuristic",
    "ground",
    "match_virtual_objects",
    "monitor",
    "plan",
    "rename_plan",
    "search",
    "world_state",
]
