"""Conceptual layer: chain graph over room categories, loopy BP, placeholders, object existence."""

from conceptual_map.conceptual.bp import BPResult, BPSettings, BPStatus, PairwiseMRF, loopy_bp
from conceptual_map.conceptual.chain_graph import ChainGraph, category_variable, property_variable
from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.conceptual.existence import (
    Location,
    ObjectLedger,
    ObjectRecord,
    RelatedSpace,
    failed_search_likelihood,
    p_at_least,
    p_at_least_one,
)
from conceptual_map.conceptual.facade import ConceptualMap
from conceptual_map.conceptual.placeholders import (
    NO_NEW_ROOM,
    Hypothesis,
    PlaceholderEvidence,
    PlaceholderPrediction,
    hypothesis_weights,
)

__all__ = [
    "NO_NEW_ROOM",
    "BPResult",
    "BPSettings",
    "BPStatus",
    "ChainGraph",
    "ConceptualError",
    "ConceptualMap",
    "Hypothesis",
    "Location",
    "ObjectLedger",
    "ObjectRecord",
    "PairwiseMRF",
    "PlaceholderEvidence",
    "PlaceholderPrediction",
    "RelatedSpace",
    "category_variable",
    "failed_search_likelihood",
    "hypothesis_weights",
    "loopy_bp",
    "p_at_least",
    "p_at_least_one",
    "property_variable",
]
