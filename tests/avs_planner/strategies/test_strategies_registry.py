"""The strategy registry: names, options checked and converted, clear errors."""

import pytest

from avs_planner.harness import EpisodeSpec
from avs_planner.strategies import StrategyError, get_strategy, strategy_names


def test_registered_names_load_a_run_function() -> None:
    assert {"switching", "exhaustive", "most-likely-room"} <= set(strategy_names())
    for name in strategy_names():
        assert callable(get_strategy(name).load())


def test_unknown_strategy_lists_the_known_ones() -> None:
    with pytest.raises(StrategyError, match=r"unknown strategy 'nope' \(known: .*switching"):
        get_strategy("nope")


def test_options_are_defaults_overridden_and_converted() -> None:
    switching = get_strategy("switching")
    options = switching.check_options({"reward": "800", "cp_node_limit": 100.0})
    assert options["reward"] == 800.0 and options["cp_node_limit"] == 100
    assert options["heuristic"] == "hadd"  # untouched default


@pytest.mark.parametrize(("given", "message"), [
    ({"nope": 1}, r"unknown option\(s\) nope \(known: "),
    ({"reward": "lots"}, r"option 'reward' must be a float"),
    ({"cp_node_limit": 2.5}, r"option 'cp_node_limit' must be an int"),
])
def test_bad_options_are_named(given: dict, message: str) -> None:
    with pytest.raises(StrategyError, match=message):
        get_strategy("switching").check_options(given)


def test_episode_spec_takes_strategy_and_options() -> None:
    spec = EpisodeSpec.from_dict({"target": "cup", "strategy": "exhaustive",
                                  "strategy_options": {"headings": "8"}})
    assert spec.strategy == "exhaustive" and spec.strategy_options["headings"] == 8
    assert EpisodeSpec.from_dict({"target": "cup"}).strategy == "switching"
    with pytest.raises(StrategyError):
        EpisodeSpec.from_dict({"target": "cup", "strategy": "random-walk"})


def test_the_registry_imports_on_its_own() -> None:
    """`avs_planner.strategies` imported first (before the episode package) is no cycle."""
    import subprocess
    import sys

    code = "import avs_planner.strategies as s; print(len(s.strategy_names()))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False)
    assert done.returncode == 0, done.stderr
