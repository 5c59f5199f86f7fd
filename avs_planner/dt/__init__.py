"""Decision-theoretic sub-planner (§2 of Göbelbecker et al., "A Planning Approach to Active Visual
Search in Large Environments"): a POMDP over view cones, solved closed-loop.

Entry point: `DTSession`. Models follow pomdp-py's layout (domain, models, agent, problem).
Several labels in one search: `MultiLabelSession` (`avs_planner.dt.multi`).
"""

from avs_planner.dt.domain import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    REJECT,
    ActionKind,
    DetectorModel,
    DTAction,
    DTObservation,
    DTState,
    ObservationKind,
    ViewCone,
)
from avs_planner.dt.errors import DtInputError, DtSessionError
from avs_planner.dt.multi import (
    LabelResult,
    LabelStatus,
    LabelTarget,
    MultiAction,
    MultiLabelProblem,
    MultiLabelResult,
    MultiLabelSession,
    MultiObservation,
    SearchMode,
)
from avs_planner.dt.policies import POLICIES, PolicyConfig, make_policy
from avs_planner.dt.pouct import SearchBudget
from avs_planner.dt.problem import DTProblem, DTRewards, TravelCosts
from avs_planner.dt.session import DTResult, DTSession, DTStatus, DTStep

__all__ = [
    "DETECTED", "NOT_DETECTED", "NOTHING", "REJECT", "POLICIES", "ActionKind", "DTAction",
    "DTObservation", "DTProblem", "DTResult", "DTRewards", "DTSession", "DTState", "DTStatus",
    "DTStep", "DetectorModel", "DtInputError", "DtSessionError", "LabelResult", "LabelStatus",
    "LabelTarget", "MultiAction", "MultiLabelProblem", "MultiLabelResult", "MultiLabelSession",
    "MultiObservation", "ObservationKind", "PolicyConfig", "SearchBudget", "SearchMode",
    "TravelCosts", "ViewCone", "make_policy",
]
