"""The switching planner (seed 003) as a strategy: the CP + DT loop of `episode.loop`.

Option `qsr_cones` (`off` by default): `on` makes view cones on a support, or in a room with
a perceived landmark, follow the QSR mixture at the perceived landmarks instead of being
uniform, when QSR descriptions are known for the target (the task's, else the default
knowledge's; `avs_planner/episode/qsr_cones.py`; on a support only with `views=cones`, FLAP's
views are left as they are). Off by default because it was not measured better: 4 desk and
kitchen worlds x 10 seeds (`python -m bench.qsr_switching`), 42 views with `on` against 36 with
`observe`. `observe`: landmarks are perceived as with `on` (the
detector is asked for their labels too) but the cones stay uniform, which isolates the
weighting in a comparison (the extra labels change the detector's noise draws)."""

from __future__ import annotations

from dataclasses import replace

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.loop import LoopConfig, SwitchingLoop
from avs_planner.episode.outcome import SearchResult
from avs_planner.episode.qsr_cones import install as install_qsr_cones
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.flap_views import VIEWS
from avs_planner.strategies.flap_views import make as make_views

QSR_CONES = ("on", "off", "observe")


def run(ctx: SearchContext) -> SearchResult:
    options = dict(ctx.options)
    views = make_views(options.pop("views", "cones"), ctx)  # FLAP views on supports
    if views is not None:
        ctx.executor.support_views, ctx.executor.on_look = views, views.on_look
    mode = str(options.pop("qsr_cones", "off")).lower()
    if mode != "off":
        qsr = install_qsr_cones(ctx.executor, ctx.qsr, ctx.target)
        if qsr is not None:
            qsr.weighting = mode == "on"
    config = LoopConfig(time_budget_s=ctx.time_budget_s, wall_budget_s=ctx.wall_budget_s,
                        dump_dir=ctx.dump_dir, **options)
    # one goal reward R per episode: the CP's objective and the DT's terminal penalties
    ctx.executor.config = replace(ctx.executor.config, miss_penalty=config.reward)
    loop = SwitchingLoop(ctx.builder, ctx.executor, ctx.trace, config, ctx.should_stop)
    loop.start_clock = ctx.start_clock
    return loop.run()


def check_options(options: dict) -> None:
    """The `views` option names a known kind of view cones, `qsr_cones` a known mode."""
    if options["views"] not in VIEWS:
        raise EpisodeError(f"option 'views' must be one of {', '.join(VIEWS)}, "
                           f"got {options['views']!r}")
    if str(options["qsr_cones"]).lower() not in QSR_CONES:
        raise EpisodeError(f"option 'qsr_cones' must be one of {', '.join(QSR_CONES)}, "
                           f"got {options['qsr_cones']!r}")
