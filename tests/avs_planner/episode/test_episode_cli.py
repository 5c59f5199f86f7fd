"""`avs simulate`: bad input exits 1 with a message naming the problem; jobs call the runner."""

from __future__ import annotations

from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.episode import EpisodeError
from avs_planner.harness import run_episode


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--target", "cerealbox", "--start", "1,2"], "expected x,y,yaw"),
        (["--target", "cerealbox", "--world", "no_such_world"], "no_such_world"),
        (["--target", "unicorn", "--strict-labels"], "unknown target label 'unicorn'"),
        (["--world", "office"], "--target LABEL"),
        (["--target", "cerealbox", "--start-room", "attic"], "attic"),
        (["--scenario", "z"], "unknown scenario 'z'"),
        (["--target", "cerealbox", "--start", "100,1,0"], "outside every room"),
        (["--target", "cup", "--generated", "3", "--world", "office"], "two different worlds"),
        (["--target", "cup", "--world", "office", "--style", "lab"], "with --generated"),
        (["--target", "cup", "--rooms", "4"], "with --generated"),
    ],
)
def test_bad_input_exits_1(argv, message, tmp_path, capsys) -> None:
    code = main(["simulate", *argv, "--out", str(tmp_path)])
    assert code == 1
    assert message in capsys.readouterr().err


def test_an_output_directory_that_cannot_be_written_is_bad_input(tmp_path, capsys) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    code = main(["simulate", "--target", "cerealbox", "--out", str(blocker / "run")])
    err = capsys.readouterr().err
    assert code == 1
    assert "--out" in err and "cannot be written" in err


def test_spec_errors_name_the_key() -> None:
    with pytest.raises(EpisodeError, match="unknown keys"):
        run_episode({"target": "cerealbox", "colour": "red"})
    with pytest.raises(EpisodeError, match="'start' must be"):
        run_episode({"target": "cerealbox", "start": [1, 2]})
    with pytest.raises(EpisodeError, match="time_budget_s"):
        run_episode({"target": "cerealbox", "time_budget_s": -1})


def test_jobs_facade_runs_an_episode(tmp_path) -> None:
    from avs_planner import jobs

    events: list[dict] = []
    summary = jobs.run_episode({"target": "cerealbox", "world": "office", "seed": 2,
                                "task_id": "t1", "output_dir": str(tmp_path)},
                               events.append, lambda: True)
    assert summary["outcome"] == "timeout"
    assert events[0]["type"] == "start" and events[-1]["type"] == "done"
    assert (tmp_path / "trace.jsonl").exists() and (tmp_path / "summary.json").exists()


def test_inline_world_file_and_start_room(tmp_path) -> None:
    world = (Path(__file__).parent / "data" / "flat_unseen.yaml").read_text()
    summary = run_episode({"target": "cerealbox", "world": None, "world_file": world,
                           "start_room": "lounge", "robot": "pioneer", "category": None,
                           "start": None, "seed": 0, "time_budget_s": 600.0},
                          None, lambda: True)
    assert summary["world"] == "flat_unseen" and summary["outcome"] == "timeout"


def test_broken_inline_world_names_the_entry() -> None:
    with pytest.raises(EpisodeError, match="^world_file: .*robot"):
        run_episode({"target": "cerealbox", "world_file": "name: x\nsize: [1, 1]\n"})
