"""Errors of the metric layer: malformed sensor data and impossible path queries."""

from __future__ import annotations

from conceptual_map.errors import MapError


class SensorDataError(MapError):
    """A scan or depth frame whose arrays do not fit together (names the field)."""


class PathQueryError(MapError):
    """A path query whose start or goal is outside the map or in blocked space."""
