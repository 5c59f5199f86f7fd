"""Exception root of `conceptual_map`."""


class MapError(Exception):
    """Root of every error the mapping package raises on purpose."""


class KnowledgeError(MapError):
    """Invalid commonsense-knowledge data (names the file and the offending entry)."""


class ExperienceError(MapError):
    """An experience store that cannot be used: missing, not such a store, or of a newer
    schema (names the file)."""
