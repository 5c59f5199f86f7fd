"""`avs simulate` with a task of several objects: repeated --target, --mode, --count,
--stop-below (docs/tasks.md), and bad combinations refused before anything runs."""

from __future__ import annotations

import json

import pytest

from avs_planner.cli import EXIT_BAD_INPUT, main


def test_any_of_two_targets(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    code = main(["simulate", "--target", "cup", "--target", "stapler", "--mode", "any",
                 "--out", str(out)])
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert code == 0 and summary["outcome"] == "found"
    assert summary["task"] == {"targets": ["cup", "stapler"], "mode": "any", "count": "one"}
    assert printed.startswith("cup or stapler: found")
    for part in summary["targets"]:
        assert f"  {part['label']}: " in printed


@pytest.mark.parametrize(("args", "message"), [
    (["--target", "cup", "--mode", "any"], "repeat --target"),
    (["--target", "cup", "--target", "cup"], "more than once"),
    (["--target", "cup", "--stop-below", "0.2"], "count: all"),
    (["--target", "cup", "--target", "book", "--count", "all"], "one label"),
    (["--target", "cup", "--count", "all", "--stop-below", "2"], "stop_below"),
])
def test_bad_task_flags_exit_1(tmp_path, args, message,
                               capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["simulate", *args, "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert code == EXIT_BAD_INPUT and message in err and "Traceback" not in err
    assert not (tmp_path / "run" / "trace.jsonl").exists()
