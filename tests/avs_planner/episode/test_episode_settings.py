"""One episode's settings are built once: the switching strategy's options decide the
executor's and state builder's settings before either exists (one R for the CP and the DT,
one look around, glimpses and the watch), and a loop refuses parts built otherwise."""

from __future__ import annotations

import pytest

from avs_planner.cp.search import DEFAULT_REWARD
from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.executor import ExecutorConfig
from avs_planner.episode.state_builder import BuilderConfig
from avs_planner.episode.trace import Trace
from avs_planner.harness import EpisodeSpec
from avs_planner.harness.runner import Episode
from avs_planner.strategies.switching.loop import LoopConfig, SwitchingLoop


def _episode(strategy: str, **options):
    episode = Episode(EpisodeSpec.from_dict({
        "target": "cerealbox", "world": "office", "seed": 1, "time_budget_s": 5.0,
        "strategy": strategy, "strategy_options": options}))
    episode.robot.world.close()
    return episode


def test_the_switching_options_build_the_executor_and_the_builder() -> None:
    episode = _episode("switching", reward=800, look_headings=4, seconds=True, watch=False)
    config = episode.executor.config
    assert (config.miss_penalty, config.look_headings, config.glimpses, config.watch) == \
        (800.0, 4, True, False)
    assert episode.executor.glimpses is not None and not episode.executor.watching
    assert episode.builder.config.seconds
    # the loop the strategy makes from the same options accepts them as they are
    loop_config = LoopConfig(reward=800, look_headings=4, seconds=True, watch=False)
    assert loop_config.configured(episode.executor, episode.builder) == []


def test_other_strategies_keep_the_executor_defaults() -> None:
    episode = _episode("exhaustive")
    assert episode.executor.config == ExecutorConfig()
    assert episode.builder.config == BuilderConfig()
    assert episode.executor.config.miss_penalty == LoopConfig().reward == DEFAULT_REWARD


def test_a_loop_refuses_an_executor_built_with_other_settings(corridor) -> None:
    _, builder, executor = corridor
    executor.config = LoopConfig().executor_config(executor.config)
    with pytest.raises(EpisodeError, match=r"miss_penalty=500.0 \(the loop's settings say 800"):
        SwitchingLoop(builder, executor, Trace(lambda: 0.0), LoopConfig(reward=800))


def test_every_switching_option_is_in_the_settings_table() -> None:
    """docs/strategies.md documents the switching strategy's settings in one table."""
    import re
    from pathlib import Path

    from avs_planner.strategies import get_strategy

    text = Path(__file__).resolve().parents[3].joinpath("docs", "strategies.md").read_text()
    table = text.split("### The switching strategy's settings", 1)[1].split("\n\n", 3)[2]
    named = set(re.findall(r"`(\w+)`", "\n".join(line.split("|")[1] for line in
                                                    table.splitlines() if line.startswith("| `"))))
    assert named == set(get_strategy("switching").options)
