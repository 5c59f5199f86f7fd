"""A building's memory across tasks (`avs_planner/episode/memory.py`, `episode/recall.py`),
end to end in the office world: the second task starts from the first's map and objects, a
moved object is not reported where it was, and one store state gives one result."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from avs_planner.episode.errors import EpisodeError
from avs_planner.harness import run_episode
from sim.world_file import WORLDS_DIR

OFFICE = (WORLDS_DIR / "office.yaml").read_text(encoding="utf-8")
CEREAL = "{name: cereal1, label: cerealbox, on: table1, offset: [0.2, -0.1]"
# the same building the next day: the cereal box was carried from the kitchen table to the
# counter
MOVED = OFFICE.replace(CEREAL, "{name: cereal1, label: cerealbox, on: counter1, "
                               "offset: [0.3, 0.0]")


def _task(world: str, memory: Path, out: Path, target: str = "cerealbox") -> dict:
    return run_episode({"target": target, "world_file": world, "seed": 1,
                        "memory": str(memory), "output_dir": str(out)})


def _events(out: Path, kind: str) -> list[dict]:
    lines = (out / "trace.jsonl").read_text(encoding="utf-8").splitlines()
    return [e for e in map(json.loads, lines) if e["type"] == kind]


@pytest.fixture(scope="module")
def first_task(tmp_path_factory):
    """Find the cereal box once with an empty memory; yields (memory dir, summary)."""
    root = tmp_path_factory.mktemp("memory")
    summary = _task(OFFICE, root / "building", root / "task1")
    return root / "building", summary


def test_first_task_starts_from_nothing_and_keeps_what_it_learned(first_task):
    memory, summary = first_task
    assert MOVED != OFFICE
    assert summary["outcome"] == "found" and summary["correct"]
    assert summary["memory"]["tasks_before"] == 0 and summary["memory"]["saved"]
    kept = json.loads((memory / "memory.json").read_text(encoding="utf-8"))
    assert kept["tasks"] == 1 and kept["format"] == 1
    # the places it drove through (more than the one it started at) and their rooms
    assert len(kept["place_map"]["places"]) >= 2 and kept["place_map"]["rooms"]
    labels = [o["label"] for o in kept["objects"]]
    assert "cerealbox" in labels  # the reported object is remembered with its time
    assert (memory / kept["grid"]).exists() and kept["grid"] == "grid-1.npz"


def test_second_task_starts_from_the_memory_and_checks_the_sighting(first_task, tmp_path):
    memory, first = first_task
    building = tmp_path / "building"
    shutil.copytree(memory, building)
    summary = _task(OFFICE, building, tmp_path / "task2")
    recalled = _events(tmp_path / "task2", "memory")[0]
    first_places = json.loads((memory / "memory.json").read_text(encoding="utf-8"))
    assert recalled["recalled"] and recalled["tasks"] == 1
    assert recalled["places"] == len(first_places["place_map"]["places"])
    assert summary["memory"]["tasks_before"] == 1 and summary["memory"]["checked"] >= 1
    assert summary["outcome"] == "found" and summary["correct"]
    # it went where it had seen the box before planning a search of the building, and the
    # box it reported is the one remembered (a check's frames can miss it, 1 in 10 or so:
    # then the watch sees it on the spot)
    checked = [e for e in _events(tmp_path / "task2", "memory") if "checked" in e]
    plans = _events(tmp_path / "task2", "plan")
    assert checked and (not plans or checked[0]["t"] <= plans[0]["t"])
    old, new = first["object"]["position"], summary["object"]["position"]
    assert ((old[0] - new[0]) ** 2 + (old[1] - new[1]) ** 2) ** 0.5 <= 1.0
    kept = json.loads((building / "memory.json").read_text(encoding="utf-8"))
    assert kept["tasks"] == 2 and kept["clock"] > first["sim_time_s"]


def test_a_moved_object_is_not_reported_where_it_was(first_task, tmp_path):
    memory, first = first_task
    old = first["object"]["position"]
    building = tmp_path / "building"
    shutil.copytree(memory, building)
    summary = _task(MOVED, building, tmp_path / "task2")
    checks = [e for e in _events(tmp_path / "task2", "memory") if "checked" in e]
    assert checks and checks[0]["checked"] == "cerealbox"
    assert checks[0]["seen"] is False and checks[0]["dropped"] is True
    if summary["object"] is not None:
        new = summary["object"]["position"]
        assert summary["correct"]
        assert abs(new[0] - old[0]) + abs(new[1] - old[1]) > 0.5
    kept = json.loads((building / "memory.json").read_text(encoding="utf-8"))
    assert not any(s["label"] == "cerealbox" and s["position"][:2] == old[:2]
                   for s in kept["sightings"])


def test_the_same_store_state_gives_the_same_episode(first_task, tmp_path):
    memory, _ = first_task
    summaries = []
    for k in range(2):
        building = tmp_path / f"building{k}"
        shutil.copytree(memory, building)
        summary = _task(OFFICE, building, tmp_path / f"task{k}", target="cup")
        summaries.append({key: summary[key] for key in
                          ("outcome", "object", "sim_time_s", "distance_m", "memory")})
    assert summaries[0] == summaries[1]


def test_bad_memory_settings_and_files_are_named(tmp_path):
    with pytest.raises(EpisodeError, match="since_s"):
        run_episode({"target": "cup", "memory": str(tmp_path), "since_s": -1})
    with pytest.raises(EpisodeError, match="'memory' must be a directory"):
        run_episode({"target": "cup", "memory": 3})
    (tmp_path / "memory.json").write_text("{not json", encoding="utf-8")
    with pytest.raises(EpisodeError, match="memory.json: not a building memory"):
        run_episode({"target": "cup", "memory": str(tmp_path)})


# the robot starts in the kitchen, its back to the table with the cereal box
KITCHEN = OFFICE.replace("robot: {model: pioneer, start: [6.0, 3.2, 0.0]}",
                         "robot: {model: pioneer, start: [3.4, 5.4, 0.0]}")


def test_a_sighting_in_view_of_the_start_is_looked_at_before_the_look_round(tmp_path):
    """`recall._check_in_view`: a remembered object the camera sees from where the robot
    stands is checked by turning to it, before and instead of the look round."""
    assert KITCHEN != OFFICE
    building = tmp_path / "building"
    first = _task(KITCHEN, building, tmp_path / "task1")
    assert first["outcome"] == "found" and first["correct"]
    second_memory = tmp_path / "again"
    shutil.copytree(building, second_memory)
    second = _task(KITCHEN, second_memory, tmp_path / "task2")
    checks = [e for e in _events(tmp_path / "task2", "memory") if "checked" in e]
    assert checks[0]["in_view"] is True and checks[0]["seen"] is True
    assert second["outcome"] == "found" and second["correct"]
    assert second["distance_m"] == 0.0
    assert [e["looked_around"] for e in _events(tmp_path / "task2", "belief")
            if "looked_around" in e][0].startswith("skipped")
    # the scan that put the robot at its place of the remembered map is in the trace, as
    # every scan's map events are (the map snapshots follow them)
    assert any("map_events" in e and e["t"] >= checks[0]["t"]
               for e in _events(tmp_path / "task2", "belief"))
    # one turn and the confirmation's frames instead of a turn all round
    assert second["sim_time_s"] < 0.6 * first["sim_time_s"]
    # the box carried away overnight: the look finds nothing there, the sighting is dropped
    # and the search goes on as without it
    moved = tmp_path / "moved"
    shutil.copytree(building, moved)
    third = _task(MOVED.replace("robot: {model: pioneer, start: [6.0, 3.2, 0.0]}",
                                "robot: {model: pioneer, start: [3.4, 5.4, 0.0]}"),
                  moved, tmp_path / "task3")
    checks = [e for e in _events(tmp_path / "task3", "memory") if "checked" in e]
    assert checks[0]["in_view"] is True and checks[0]["dropped"] is True
    assert third["outcome"] == "found" and third["correct"]
    assert third["object"]["position"][:2] != first["object"]["position"][:2]
