"""The DT over several labels: one view-cone search whose looks serve every open label.

Each label's location is independent (in one cone or in none), so the belief is a product of
single-label beliefs; CONFIRM(label, cone) and REJECT(label) close one label, and the search
ends when every label is decided (mode "all") or one is confirmed (mode "any"). Entry point:
`MultiLabelSession`. Models follow pomdp-py's layout like the single-label package.
"""

from avs_planner.dt.multi.belief import MultiLabelBelief
from avs_planner.dt.multi.domain import (
    OPEN,
    MultiAction,
    MultiLabelState,
    MultiObservation,
    SearchMode,
)
from avs_planner.dt.multi.exact import MultiExactPolicy, MultiExactSolver, evaluate_multi_policy
from avs_planner.dt.multi.lookahead import MultiLookaheadPolicy
from avs_planner.dt.multi.policies import MULTI_POLICIES, MultiPolicy, make_multi_policy
from avs_planner.dt.multi.problem import LabelTarget, MultiLabelProblem
from avs_planner.dt.multi.session import (
    LabelResult,
    LabelStatus,
    MultiLabelResult,
    MultiLabelSession,
    MultiStep,
)

__all__ = [
    "MULTI_POLICIES", "OPEN", "LabelResult", "LabelStatus", "LabelTarget", "MultiAction",
    "MultiExactPolicy", "MultiExactSolver", "MultiLookaheadPolicy", "MultiLabelBelief",
    "MultiLabelProblem", "MultiLabelResult", "MultiLabelSession", "MultiLabelState",
    "MultiObservation", "MultiPolicy", "MultiStep", "SearchMode", "evaluate_multi_policy",
    "make_multi_policy",
]
