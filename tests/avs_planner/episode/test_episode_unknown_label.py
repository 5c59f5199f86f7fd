"""A target label the knowledge does not list: searched for with the knowledge's
uninformed prior and a `warning` event, or refused with `strict_labels`."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.episode import EpisodeError
from avs_planner.harness import EpisodeSpec, run_episode
from avs_planner.harness.validate import check_task

# flap_two_rooms holds two bottles (one on a table in room_a, one on a shelf in room_b); the
# robot starts in room_b, facing room_a's door
BOTTLE = {"target": "bottle", "world": "flap_two_rooms", "start": [7.5, 2.5, 3.14],
          "seed": 0, "time_budget_s": 600.0}


def test_an_unknown_label_is_found_by_the_switching_planner_with_a_warning(tmp_path) -> None:
    summary = run_episode({**BOTTLE, "output_dir": str(tmp_path)})
    assert summary["outcome"] == "found" and summary["correct"]
    assert summary["object"]["label"] == "bottle"
    assert summary["dt_confirmed"] + summary["dt_rejected"] == summary["dt_calls"]
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").open()]
    warnings = [e for e in events if e["type"] == "warning" and e.get("label") == "bottle"]
    assert len(warnings) == 1 and "no priors" in warnings[0]["detail"]
    types = [e["type"] for e in events]
    assert types.index("start") < types.index("warning") < types.index("plan")


def test_strict_labels_refuses_an_unknown_label(tmp_path, capsys) -> None:
    assert not EpisodeSpec.from_dict({"target": "bottle"}).strict_labels
    with pytest.raises(EpisodeError, match="unknown target label 'bottle'"):
        run_episode({**BOTTLE, "strict_labels": True})
    with pytest.raises(EpisodeError, match="'strict_labels' must be true or false"):
        EpisodeSpec.from_dict({"target": "bottle", "strict_labels": "yes"})
    code = main(["simulate", "--world", "flap_two_rooms", "--target", "bottle",
                 "--strict-labels", "--out", str(tmp_path)])
    assert code == 1
    assert "unknown target label 'bottle'" in capsys.readouterr().err
    assert not (tmp_path / "trace.jsonl").exists()  # refused before the run


def test_task_check_accepts_an_unknown_label_only_when_not_strict() -> None:
    import sim

    world = Path(sim.__file__).parent / "worlds" / "flap_two_rooms.yaml"
    task = {"target": "bottle", "world": "flap_two_rooms"}
    assert [p.field for p in check_task(task, world)] == ["target"]  # unsaid: strict
    assert [p.field for p in check_task({**task, "strict_labels": True}, world)] == ["target"]
    assert check_task({**task, "strict_labels": False}, world) == []
    assert [p.field for p in check_task({**task, "strict_labels": 1}, world)] == [
        "strict_labels", "target"]


def test_labels_and_categories_are_read_whatever_their_case() -> None:
    """"CerealBox" is the knowledge's cerealbox and "Living Room" its living_room, for the
    task check (the service) and the episode alike; a label that differs in more than case
    and separators is still a label the knowledge does not list."""
    from conceptual_map.knowledge import load_knowledge

    knowledge = load_knowledge()
    assert knowledge.spelled("CerealBox") == "cerealbox"
    assert knowledge.spelled(" Living Room ") == "living_room"
    assert knowledge.spelled("living-room") == "living_room"
    assert knowledge.spelled("Cereal Box") == "Cereal Box"  # not listed: unchanged
    task = {"target": "CerealBox", "category": "KITCHEN", "world": "office"}
    import sim

    office = Path(sim.__file__).parent / "worlds" / "office.yaml"
    assert check_task(task, office) == []
    summary = run_episode({**task, "seed": 1, "time_budget_s": 20.0})
    assert summary["target"] == "cerealbox"
