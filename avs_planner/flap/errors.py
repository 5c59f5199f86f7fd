"""Errors of the FLAP view planner, under the package's one exception root."""

from __future__ import annotations

from avs_planner.errors import AvsError


class FlapError(AvsError):
    """A FLAP query that cannot be answered as asked (bad volume, probability or option)."""
