"""Decision-theoretic sub-planner (§2 of Göbelbecker et al., "A Planning Approach to Active Visual
Search in Large Environments"): a POMDP over view cones, solved closed-loop.

Entry point: `DTSession`. Models follow pomdp-py's layout (domain, models, agent, problem).
Several labels in one search: `MultiLabelSession` (`avs_planner.dt.multi`).

The names below are loaded from their modules on first use (PEP 562), so importing the
package imports no solver: the mind's side holds view cones and the detector model
(`inputs.py`, plain values) in every episode, and pomdp-py (~0.7 s to import) is loaded only
when an episode runs a DT session.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the same names, for type checkers and editors
    from avs_planner.dt.domain import (
        DETECTED,
        NOT_DETECTED,
        NOTHING,
        REJECT,
        ActionKind,
        DTAction,
        DTObservation,
        DTState,
        ObservationKind,
    )
    from avs_planner.dt.errors import DtInputError, DtSessionError
    from avs_planner.dt.inputs import DetectorModel, ViewCone
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

_HOMES = {
    "domain": ("DETECTED", "NOT_DETECTED", "NOTHING", "REJECT", "ActionKind", "DTAction",
               "DTObservation", "DTState", "ObservationKind"),
    "errors": ("DtInputError", "DtSessionError"),
    "inputs": ("DetectorModel", "ViewCone"),
    "multi": ("LabelResult", "LabelStatus", "LabelTarget", "MultiAction", "MultiLabelProblem",
              "MultiLabelResult", "MultiLabelSession", "MultiObservation", "SearchMode"),
    "policies": ("POLICIES", "PolicyConfig", "make_policy"),
    "pouct": ("SearchBudget",),
    "problem": ("DTProblem", "DTRewards", "TravelCosts"),
    "session": ("DTResult", "DTSession", "DTStatus", "DTStep"),
}
_HOME = {name: module for module, names in _HOMES.items() for name in names}

__all__ = [  # the same names as _HOMES (a test checks it): listed for readers and linters
    "DETECTED", "NOT_DETECTED", "NOTHING", "REJECT", "POLICIES", "ActionKind", "DTAction",
    "DTObservation", "DTProblem", "DTResult", "DTRewards", "DTSession", "DTState", "DTStatus",
    "DTStep", "DetectorModel", "DtInputError", "DtSessionError", "LabelResult", "LabelStatus",
    "LabelTarget", "MultiAction", "MultiLabelProblem", "MultiLabelResult", "MultiLabelSession",
    "MultiObservation", "ObservationKind", "PolicyConfig", "SearchBudget", "SearchMode",
    "TravelCosts", "ViewCone", "make_policy",
]


def __getattr__(name: str) -> Any:
    """`avs_planner.dt.NAME`: imported from its module on first use, then kept here."""
    module = _HOME.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
