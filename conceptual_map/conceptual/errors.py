"""Errors of the conceptual layer: unknown ids, labels or values, malformed models."""

from conceptual_map.errors import MapError


class ConceptualError(MapError):
    """Bad input to the conceptual map (names the room, place, label or value at fault)."""
