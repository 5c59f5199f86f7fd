"""Search strategies, chosen by name from one registry.

Every strategy runs on the same robot adapter, maps, conceptual map and trace (a
`SearchContext`), and returns a `SearchResult`; the episode runner writes the same summary for
all of them, so `avs simulate --strategy`, campaigns and the service compare them on the same
worlds, targets and seeds. A strategy is a function `run(ctx) -> SearchResult` in a module of
this package; the registry keeps its name beside it and imports it on first use.
"""

from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.registry import (
    STRATEGIES,
    Strategy,
    StrategyError,
    get_strategy,
    strategy_names,
)

__all__ = ["STRATEGIES", "SearchContext", "Strategy", "StrategyError", "get_strategy",
           "strategy_names"]
