"""Errors of the QSR layer (bad QSR data files raise `KnowledgeError` instead)."""

from conceptual_map.errors import MapError


class QsrError(MapError):
    """A QSR model that cannot be built: no landmark for a description, too few samples."""
