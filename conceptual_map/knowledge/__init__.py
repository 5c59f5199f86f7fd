"""Default commonsense knowledge (YAML data) and its validating loader."""

from conceptual_map.knowledge.loader import DEFAULT_KNOWLEDGE_PATH, load_knowledge, parse_knowledge
from conceptual_map.knowledge.model import (
    RELATIONS,
    Knowledge,
    MobilityModel,
    PlaceholderModel,
    PropertyModel,
    UnknownLabelModel,
)

__all__ = [
    "DEFAULT_KNOWLEDGE_PATH",
    "RELATIONS",
    "Knowledge",
    "MobilityModel",
    "PlaceholderModel",
    "PropertyModel",
    "UnknownLabelModel",
    "load_knowledge",
    "parse_knowledge",
]
