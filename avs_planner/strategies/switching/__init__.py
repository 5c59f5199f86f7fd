"""The switching planner of Göbelbecker et al., "A Planning Approach to Active Visual Search in
Large Environments", as a strategy: the CP + DT loop of `loop.py`.

Option `qsr_cones` (`off` by default): `on` makes view cones on a support, or in a room with
a perceived landmark, follow the QSR mixture at the perceived landmarks instead of being
uniform, when QSR descriptions are known for the target (the task's, else the default
knowledge's; `avs_planner/strategies/switching/qsr_cones.py`; on a support only with
`views=cones`, FLAP's views are left as they are). Off by default because it was not measured
better: 4 desk and kitchen worlds x 10 seeds (`python -m bench.qsr_switching`), 42 views with
`on` against 36 with `observe`. `observe`: landmarks are perceived as with `on` (the
detector is asked for their labels too) but the cones stay uniform, which isolates the
weighting in a comparison (the extra labels change the detector's noise draws)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.executor import ExecutorConfig
from avs_planner.episode.outcome import SearchResult
from avs_planner.episode.state_builder import BuilderConfig
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.switching.loop import LoopConfig, SwitchingLoop
from avs_planner.strategies.switching.qsr_cones import install as install_qsr_cones

if TYPE_CHECKING:
    from avs_planner.strategies.flap_views import FlapViews

VIEWS = ("cones", "flap")  # the `views` option: the 2D cones, or FLAP's views on supports
QSR_CONES = ("on", "off", "observe")
OWN_OPTIONS = ("views", "qsr_cones")  # the strategy's own options; the rest are the loop's


def run(ctx: SearchContext) -> SearchResult:
    options = dict(ctx.options)
    views = _views(options.pop("views", "cones"), ctx)  # FLAP views on supports
    if views is not None:
        ctx.executor.support_views, ctx.executor.on_look = views, views.on_look
    mode = str(options.pop("qsr_cones", "off")).lower()
    if mode != "off":
        qsr = install_qsr_cones(ctx.executor, ctx.qsr, ctx.target)
        if qsr is not None:
            qsr.weighting = mode == "on"
    config = loop_config(options, time_budget_s=ctx.time_budget_s,
                         wall_budget_s=ctx.wall_budget_s, dump_dir=ctx.dump_dir)
    if ctx.stop_below is not None:
        # counting every instance: the task's level decides when to stop (the caller ends
        # the search there), not the reward against costs; a plan still needs the CP's
        # success threshold
        config = replace(config, worth_test=False, stop_rule=False)
    loop = SwitchingLoop(ctx.builder, ctx.executor, ctx.trace, config, ctx.should_stop)
    loop.start_clock = ctx.start_clock
    return loop.run()


def _views(kind: str, ctx: SearchContext) -> FlapViews | None:
    """The cone maker for the `views` option (None: the 2D cones). FLAP (`flap_views.py`)
    is imported only when asked for: it and the parts of scipy it needs take ~0.08 s to
    import, a tenth of an episode's start."""
    if kind == "cones":
        return None
    from avs_planner.strategies.flap_views import make

    return make(kind, ctx)


def loop_config(options: Mapping[str, Any], **episode: Any) -> LoopConfig:
    """The episode's one settings object: the loop's options (without the strategy's own
    `views` and `qsr_cones`) and what the episode spec gives (budgets, dump directory)."""
    return LoopConfig(**{k: v for k, v in options.items() if k not in OWN_OPTIONS}, **episode)


def configure(options: Mapping[str, Any]) -> tuple[ExecutorConfig, BuilderConfig]:
    """The executor's and state builder's settings, built once from the episode's options
    before either exists (`Strategy.configure`): one R, one look around, one watch."""
    config = loop_config(options)
    return config.executor_config(), config.builder_config()


def check_options(options: dict) -> None:
    """The `views` option names a known kind of view cones, `qsr_cones` a known mode."""
    if options["views"] not in VIEWS:
        raise EpisodeError(f"option 'views' must be one of {', '.join(VIEWS)}, "
                           f"got {options['views']!r}")
    if str(options["qsr_cones"]).lower() not in QSR_CONES:
        raise EpisodeError(f"option 'qsr_cones' must be one of {', '.join(QSR_CONES)}, "
                           f"got {options['qsr_cones']!r}")
