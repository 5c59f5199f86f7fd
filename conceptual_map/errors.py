"""Exception root of `conceptual_map`."""


class MapError(Exception):
    """Root of every error the mapping package raises on purpose."""


class KnowledgeError(MapError):
    """Invalid commonsense-knowledge data (names the file and the offending entry)."""
