"""Errors of the decision-theoretic (POMDP) sub-planner."""

from __future__ import annotations

from avs_planner.errors import AvsError


class DtInputError(AvsError):
    """Bad input to the DT planner (view cones, costs, detector, rewards); names the culprit."""


class DtSessionError(AvsError):
    """A DT session was driven wrongly (update without a matching action, act after the end)."""
