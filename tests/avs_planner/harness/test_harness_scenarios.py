"""The active visual search paper's six office runs (Fig. 3 a-f) and a floor plan no other test
has seen.

Each run takes 2-10 s of wall time, and all six run at three sensor-noise seeds, so they are
marked slow; scenario (a) also runs in the default suite (test_episode_loop.py).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from avs_planner.harness import run_episode
from avs_planner.harness.scenarios import builtin_scenarios, load_scenario

DATA = Path(__file__).parents[1] / "episode" / "data"  # the hand-made worlds of the episode tests


def test_all_six_seed_runs_are_scenario_files() -> None:
    assert builtin_scenarios() == ["a", "b", "c", "d", "e", "f"]
    expected = {name: load_scenario(name).expected for name in builtin_scenarios()}
    assert expected == {"a": "found", "b": "found", "c": "gave_up", "d": "found",
                        "e": "gave_up", "f": "found"}


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("name", ["a", "b", "c", "d", "e", "f"])
def test_seed_scenario_behaves_as_in_the_seed(name: str, seed: int) -> None:
    scenario = load_scenario(name)
    summary = run_episode(scenario.episode_spec(seed=seed), None, None)
    assert summary["outcome"] == scenario.expected, summary["reason"]
    if scenario.expected == "found":
        assert summary["correct"], summary["object"]


@pytest.mark.slow
def test_an_unseen_floor_plan() -> None:
    summary = run_episode({"target": "cerealbox", "world": str(DATA / "flat_unseen.yaml"),
                           "seed": 1}, None, None)
    assert summary["outcome"] == "found" and summary["object"]["truth"] == "cereal9"


@pytest.mark.slow
def test_the_pr2_finds_the_cereal_box_too() -> None:
    summary = run_episode(load_scenario("a").episode_spec(seed=1, robot="pr2"), None, None)
    assert summary["robot"] == "pr2"
    assert summary["outcome"] == "found" and summary["correct"]
