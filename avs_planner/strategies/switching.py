"""The switching planner (seed 003) as a strategy: the CP + DT loop of `episode.loop`."""

from __future__ import annotations

from avs_planner.episode.loop import LoopConfig, SwitchingLoop
from avs_planner.episode.outcome import SearchResult
from avs_planner.strategies.context import SearchContext


def run(ctx: SearchContext) -> SearchResult:
    config = LoopConfig(time_budget_s=ctx.time_budget_s, wall_budget_s=ctx.wall_budget_s,
                        dump_dir=ctx.dump_dir, **ctx.options)
    loop = SwitchingLoop(ctx.builder, ctx.executor, ctx.trace, config, ctx.should_stop)
    loop.start_clock = ctx.start_clock
    return loop.run()
