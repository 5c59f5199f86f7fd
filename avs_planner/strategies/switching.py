"""The switching planner (seed 003) as a strategy: the CP + DT loop of `episode.loop`."""

from __future__ import annotations

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.loop import LoopConfig, SwitchingLoop
from avs_planner.episode.outcome import SearchResult
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.flap_views import VIEWS
from avs_planner.strategies.flap_views import make as make_views


def run(ctx: SearchContext) -> SearchResult:
    options = dict(ctx.options)
    views = make_views(options.pop("views", "cones"), ctx)  # FLAP views on supports
    if views is not None:
        ctx.executor.support_views, ctx.executor.on_look = views, views.on_look
    config = LoopConfig(time_budget_s=ctx.time_budget_s, wall_budget_s=ctx.wall_budget_s,
                        dump_dir=ctx.dump_dir, **options)
    loop = SwitchingLoop(ctx.builder, ctx.executor, ctx.trace, config, ctx.should_stop)
    loop.start_clock = ctx.start_clock
    return loop.run()


def check_options(options: dict) -> None:
    """The `views` option names a known kind of view cones."""
    if options["views"] not in VIEWS:
        raise EpisodeError(f"option 'views' must be one of {', '.join(VIEWS)}, "
                           f"got {options['views']!r}")
