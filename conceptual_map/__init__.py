"""The robot's spatial knowledge: metric maps, place map, conceptual layer (chain graph), and
QSR models (`conceptual_map.qsr`: relation mixtures and supporting planes, after the QSR paper
by Kunze et al.).

Never imports `sim`: everything it knows comes from sensor data handed over by the executor.
The conceptual layer's facade is `conceptual_map.ConceptualMap` (imported on first use, so
`import conceptual_map.metric` stays light).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from conceptual_map.conceptual.facade import ConceptualMap

__all__ = ["ConceptualMap"]


def __getattr__(name: str) -> Any:
    if name == "ConceptualMap":
        from conceptual_map.conceptual.facade import ConceptualMap

        return ConceptualMap
    raise AttributeError(f"module 'conceptual_map' has no attribute {name!r}")
