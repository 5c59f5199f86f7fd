"""The switching planner (seed 003) as a strategy: the CP + DT loop of `episode.loop`.

Option `qsr_cones` (`on` by default): when QSR descriptions are known for the target (the
task's, else the default knowledge's), view cones on a support, or in a room with a perceived
landmark, follow the QSR mixture at the perceived landmarks instead of being uniform
(`avs_planner/episode/qsr_cones.py`). `off`: not at all; `observe`: landmarks are perceived
as with `on` (the detector is asked for their labels too) but the cones stay uniform, which
isolates the weighting in a comparison (the extra labels change the detector's noise draws)."""

from __future__ import annotations

from avs_planner.episode.loop import LoopConfig, SwitchingLoop
from avs_planner.episode.outcome import SearchResult
from avs_planner.episode.qsr_cones import install as install_qsr_cones
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.registry import StrategyError

# options of this strategy beyond the loop's (LoopConfig)
OPTIONS = {"qsr_cones": "on"}
QSR_CONES = ("on", "off", "observe")


def run(ctx: SearchContext) -> SearchResult:
    options = dict(ctx.options)
    mode = str(options.pop("qsr_cones", OPTIONS["qsr_cones"])).lower()
    if mode not in QSR_CONES:
        raise StrategyError(f"strategy 'switching': option 'qsr_cones' must be one of "
                            f"{', '.join(QSR_CONES)}, got {mode!r}")
    if mode != "off":
        qsr = install_qsr_cones(ctx.executor, ctx.qsr, ctx.target)
        if qsr is not None:
            qsr.weighting = mode == "on"
    config = LoopConfig(time_budget_s=ctx.time_budget_s, wall_budget_s=ctx.wall_budget_s,
                        dump_dir=ctx.dump_dir, **options)
    loop = SwitchingLoop(ctx.builder, ctx.executor, ctx.trace, config, ctx.should_stop)
    loop.start_clock = ctx.start_clock
    return loop.run()
