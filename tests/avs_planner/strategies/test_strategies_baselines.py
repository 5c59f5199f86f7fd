"""The baselines search the office with the same robot, maps and detector as the planner."""

import json

import pytest

from avs_planner.episode import run_episode
from avs_planner.episode.scenarios import load_scenario


@pytest.mark.parametrize("strategy", ["exhaustive", "most-likely-room"])
def test_baseline_finds_the_cereal_box_and_writes_the_usual_summary(strategy, tmp_path):
    spec = load_scenario("a").episode_spec(strategy=strategy, seed=1,
                                           output_dir=str(tmp_path))
    summary = run_episode(spec)
    assert summary["strategy"] == strategy
    assert summary["outcome"] == "found" and summary["correct"]
    assert summary["plans"] == 0 and summary["views_processed"] > 0
    assert summary["sim_time_s"] > 0
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").read_text().splitlines()]
    assert events[0]["type"] == "start" and events[0]["strategy"] == strategy
    assert events[-1]["type"] == "done" and events[-1]["outcome"] == "found"
    assert json.loads((tmp_path / "summary.json").read_text())["strategy"] == strategy


def test_exhaustive_gives_up_on_an_absent_label_and_reports_nothing():
    spec = load_scenario("a").episode_spec(strategy="exhaustive", target="toilet", seed=0,
                                           time_budget_s=3000)
    summary = run_episode(spec)
    assert summary["outcome"] == "gave_up", summary["reason"]
    assert summary["object"] is None


def test_most_likely_room_starts_with_the_likeliest_room():
    """From the corridor, a cereal box is likelier behind the kitchen's door than in the
    corridor: the first ranked choice is unexplored space, not the corridor it stands in."""
    spec = load_scenario("a").episode_spec(strategy="most-likely-room", seed=2)
    events = []
    run_episode(spec, events.append)
    choices = [e for e in events if e["type"] == "belief" and "most_likely" in e]
    assert choices, "the strategy never ranked a room or placeholder"
    assert all(0.0 <= e["probability"] <= 1.0 for e in choices)
    assert choices[0]["kind"] == "placeholder"
