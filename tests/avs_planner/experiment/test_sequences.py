"""Campaign sequences: a building's tasks day after day, memory on and off; parsing, expansion,
running in order with the memory each episode left, resuming, and the report's section."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import yaml

from avs_planner.experiment import CampaignError, load_campaign
from avs_planner.experiment.campaign import HELDOUT_WORLD_SEEDS_FROM, parse_campaign
from avs_planner.experiment.report import render
from avs_planner.experiment.results import COLUMNS, read_results
from avs_planner.experiment.runner import RunOptions, run_campaign
from avs_planner.experiment.subjects import generated_instances

FAKE = Path(__file__).with_name("fake_runner.py")
SEQ = {"name": "seq", "worlds": [{"generate": {"seeds": "330", "style": "office"}}],
       "robots": ["pioneer"], "seeds": 1,
       "sequence": {"tasks": 3, "move": 0.2, "since_s": 86400, "memory": ["on", "off"]}}


def parse(data):
    return parse_campaign(data, "c.yaml", Path("."))


@pytest.mark.parametrize(("change", "fragment"), [
    ({"sequence": [3]}, "c.yaml: sequence: a mapping {tasks: N"),
    ({"sequence": {"tasks": 3, "days": 2}}, "c.yaml: sequence: unknown keys ['days']"),
    ({"sequence": {"move": 0.2}}, "c.yaml: sequence.tasks: required"),
    ({"sequence": {"tasks": 0}}, "c.yaml: sequence.tasks: a whole number of tasks from 1"),
    ({"sequence": {"tasks": True}}, "c.yaml: sequence.tasks: a whole number"),
    ({"sequence": {"tasks": 3, "move": 1.5}}, "c.yaml: sequence.move: a probability in [0, 1]"),
    ({"sequence": {"tasks": 3, "doors": "some"}}, "c.yaml: sequence.doors: a probability"),
    ({"sequence": {"tasks": 3, "since_s": -1}}, "c.yaml: sequence.since_s: simulated seconds"),
    ({"sequence": {"tasks": 3, "memory": ["on", "maybe"]}},
     "c.yaml: sequence.memory[1]: 'on' or 'off', got 'maybe'"),
    ({"sequence": {"tasks": 3, "memory": ["on", "on"]}}, "sequence.memory[1]: 'on' is listed"),
    ({"sequence": {"tasks": 3, "memory": []}}, "sequence.memory: a non-empty list"),
    ({"targets": ["cup"]}, "c.yaml: targets: a sequence draws each task's target"),
    ({"worlds": ["office"]}, "c.yaml: worlds[0]: a sequence runs on generated buildings"),
    ({"worlds": [{"generate": {"seeds": "330"}, "targets": "auto"}]},
     "c.yaml: worlds[0]: unknown keys ['targets']"),
    ({"worlds": [{"generate": {"seeds": "330", "rooms": 0}}]},
     "c.yaml: worlds[0].generate.rooms: a positive number of rooms"),
])
def test_a_bad_sequence_is_refused_naming_the_key(change, fragment):
    with pytest.raises(CampaignError) as info:
        parse({**SEQ, **change}).runs()
    assert fragment in str(info.value), str(info.value)


def test_scenarios_cannot_be_a_sequence():
    data = {k: v for k, v in SEQ.items() if k != "worlds"}
    with pytest.raises(CampaignError, match="c.yaml: sequence: a sequence runs on generated"):
        parse({**data, "scenarios": ["a"]})


def test_yaml_on_and_off_are_the_arms():
    text = "tasks: 2\nmemory: [on, off]\n"
    campaign = parse({**SEQ, "sequence": yaml.safe_load(text)})
    assert campaign.sequence.memory == ("on", "off")
    assert parse({**SEQ, "sequence": {"tasks": 2, "memory": "off"}}).sequence.memory == ("off",)


def test_a_sequence_expands_into_ordered_tasks_per_arm_with_its_memory_directory():
    runs = parse(SEQ).runs()
    assert len(runs) == 6
    on, off = runs[:3], runs[3:]
    assert [r.task_index for r in on] == [0, 1, 2] == [r.task_index for r in off]
    assert {r.memory for r in on} == {"on"} and {r.memory for r in off} == {"off"}
    assert len({r.sequence for r in on}) == 1 and on[0].sequence != off[0].sequence
    assert on[0].sequence == "gen-office-330-switching-pioneer-s1-memory-on"
    for i, (a, b) in enumerate(zip(on, off, strict=True)):
        assert a.subject.target == b.subject.target  # the arms search for the same labels
        assert a.episode["generate"] == {"seed": 330, "style": "office", "rooms": None,
                                         "day": i, "move": 0.2, "doors": 0.0}
        assert a.episode["memory"] == "memory/gen-office-330-pioneer-switching-s1"
        assert a.episode["since_s"] == 86400.0
        assert "memory" not in b.episode and "since_s" not in b.episode
        assert a.subject.expected == "found"
        present = generated_instances(330, "office", None, day=i, move=0.2, doors=0.0)
        assert a.subject.target in present
        assert a.run_id == f"gen-office-330-t0{i}-{a.subject.target}-switching-pioneer-s1-memory-on"
        assert a.columns()["task_index"] == i and a.columns()["memory"] == "on"
    assert [r.subject.target for r in parse(SEQ).runs()] == [r.subject.target for r in runs]
    targets = [r.subject.target for r in parse({**SEQ, "sequence": {"tasks": 10}}).runs()[:10]]
    assert len(set(targets)) > 1  # drawn per task, not one label for all


def run(out: Path, data=None, **options):
    campaign = parse(data or SEQ)
    return run_campaign(campaign, RunOptions(out, workers=2,
                                             episode_runner=f"{FAKE}:remembering", **options))


def executions(out: Path) -> list[str]:
    log = out / "executions.log"
    return log.read_text().split() if log.exists() else []


def seen(out: Path) -> dict[str, list[str]]:
    return {p.parent.name: json.loads(p.read_text())["memory_seen"]
            for p in (out / "runs").glob("*/summary.json")}


def test_a_sequence_runs_in_order_each_episode_reading_the_memory_before_it(tmp_path):
    result = run(tmp_path)
    runs = parse(SEQ).runs()
    log = executions(tmp_path)
    for arm in ("on", "off"):
        ids = [r.run_id for r in runs if r.memory == arm]
        assert [x for x in log if x in ids] == ids  # in order
    memory = {r.run_id: r.task_index for r in runs if r.memory == "on"}
    got = seen(tmp_path)
    for run_id, index in memory.items():
        assert got[run_id] == [f"day{d}" for d in range(index)]
        assert (tmp_path / "runs" / run_id / "memory" / f"day{index}").exists()
    assert all(got[r.run_id] == [] for r in runs if r.memory == "off")
    assert (tmp_path / "memory" / "gen-office-330-pioneer-switching-s1").is_dir()
    rows = read_results(result.results)
    assert [(r["task_index"], r["memory"]) for r in rows] == [
        (0, "on"), (1, "on"), (2, "on"), (0, "off"), (1, "off"), (2, "off")]
    assert {r["sequence"] for r in rows} == {runs[0].sequence, runs[3].sequence}
    record = json.loads((tmp_path / "runs" / runs[1].run_id / "record.json").read_text())
    assert record["spec"]["memory"] == str(
        (tmp_path / "memory" / "gen-office-330-pioneer-switching-s1").resolve())


def test_resume_skips_finished_episodes_and_starts_from_the_memory_they_left(tmp_path):
    runs = parse(SEQ).runs()
    on = [r.run_id for r in runs if r.memory == "on"]
    off = [r.run_id for r in runs if r.memory == "off"]
    run(tmp_path, limit=1)  # the first task of the first sequence only
    assert executions(tmp_path) == [on[0]]
    (tmp_path / "memory" / "gen-office-330-pioneer-switching-s1" / "stray").write_text("x")
    result = run(tmp_path)
    assert sorted(executions(tmp_path)) == sorted(on + off)  # none twice
    assert result.progress.skipped == 1
    assert seen(tmp_path)[on[1]] == ["day0"]  # from the copy task 0 left, not the stray
    # task 1 of each arm lost: with memory, task 2 read what it wrote, so it runs again too
    for run_id in (on[1], off[1]):
        shutil.rmtree(tmp_path / "runs" / run_id)
    run(tmp_path)
    log = executions(tmp_path)
    assert log[6:] and sorted(log[6:]) == sorted([on[1], on[2], off[1]])
    assert seen(tmp_path)[on[2]] == ["day0", "day1"]  # task 2's own memory was not kept
    run(tmp_path)
    assert len(executions(tmp_path)) == 9  # all done: nothing runs


def _row(world, index, memory, sim_time, found=True, strategy="switching", seed=1):
    return {**dict.fromkeys(COLUMNS), "run_id": f"{world}-{index}-{memory}", "scenario": "",
            "world": world,
            "group": "gen-office", "target": "cup", "expected": "found",
            "strategy": strategy, "robot": "pioneer", "seed": seed, "task": "",
            "task_labels": "", "sequence": f"{world}-{memory}", "task_index": index,
            "memory": memory, "status": "ok", "error": None,
            "outcome": "found" if found else "timeout", "reason": "", "correct": found,
            "success": found, "correct_give_up": None, "false_report": False,
            "sim_time_s": sim_time, "distance_m": 1.0, "plans": 1, "replans": 0,
            "cp_s_per_plan": 0.1, "dt_s_per_action": 0.1, "dt_calls": 0, "commit": "abc1234"}


def test_the_report_pairs_memory_on_and_off_per_building_and_task(tmp_path):
    rows = []
    for world in ("gen-office-330", "gen-office-331"):
        rows += [_row(world, 0, "on", 100.0), _row(world, 0, "off", 100.0)]
        rows += [_row(world, 1, "on", 50.0), _row(world, 1, "off", 100.0)]
        rows += [_row(world, 2, "on", 25.0), _row(world, 2, "off", 100.0, found=False)]
    text = render(rows, {"name": "seq"}, tmp_path / "report.md")
    (tmp_path / "report.md").write_text(text)
    assert "## Memory: tasks on later days of a building" in text
    lines = text.splitlines()
    later_on = next(x for x in lines if x.startswith("| switching | ≥ 1 | on |"))
    assert "4/4 = 100%" in later_on and "0.50 [0.50, 0.50] (n 2)" in later_on
    later_off = next(x for x in lines if x.startswith("| switching | ≥ 1 | off |"))
    assert "2/4 = 50%" in later_off
    control = next(x for x in lines if x.startswith("| switching | 0 | on |"))
    assert "1.00 [1.00, 1.00] (n 2)" in control
    assert "## Memory: by task index" in text
    assert any(x.startswith("| switching | 2 | 2/2 = 100%") and "0/2 = 0%" in x for x in lines)


def test_the_memory_campaigns_keep_to_their_seed_ranges():
    dev, heldout = load_campaign("memory-dev"), load_campaign("memory-heldout")
    for campaign, noise in ((dev, (1,)), (heldout, (100,))):
        assert campaign.sequence.tasks == 10 and campaign.sequence.memory == ("on", "off")
        assert campaign.sequence.move == 0.2 and campaign.seeds == noise
        assert [s.label for s in campaign.strategies] == ["switching"]
        assert campaign.robots == ("pioneer",)
    seeds = {s.spec["generate"]["seed"] for s in dev.subjects}
    assert seeds == set(range(330, 340)) and max(seeds) < HELDOUT_WORLD_SEEDS_FROM
    held = {s.spec["generate"]["seed"] for s in heldout.subjects}
    assert held == set(range(10100, 10110))
    assert len(dev.runs()) == 200 and len(heldout.runs()) == 200
    header = Path(heldout.source).read_text(encoding="utf-8").split("\nname:")[0]
    assert "NOTHING may be tuned" in header and "10000 and up" in header


@pytest.mark.slow
def test_the_ray_backend_runs_a_sequence_in_order_with_its_memory(tmp_path):
    pytest.importorskip("ray", reason="Ray is not installed (pip install '.[ray]')")
    run(tmp_path, backend="ray")
    runs = parse(SEQ).runs()
    log = executions(tmp_path)
    for arm in ("on", "off"):
        ids = [r.run_id for r in runs if r.memory == arm]
        assert [x for x in log if x in ids] == ids
    got = seen(tmp_path)
    assert all(got[r.run_id] == [f"day{d}" for d in range(r.task_index)]
               for r in runs if r.memory == "on")
