"""`avs simulate`'s progress: rewritten in place on a terminal, lines in a log."""

from __future__ import annotations

from avs_planner.cli.simulate import _Progress

EVENTS = [
    {"type": "plan", "t": 10.0},
    {"type": "action", "t": 10.0, "action": "(move place1 placeholder2)", "status": "start"},
    {"type": "action", "t": 25.0, "action": "(move place1 placeholder2)", "status": "done"},
    {"type": "dt", "t": 40.0, "result": "rejected"},
    {"type": "action", "t": 41.0, "action": "(move place2 place3)", "status": "failed"},
    {"type": "map", "t": 41.0},
    {"type": "done", "t": 50.0, "outcome": "found"},
]


def _run(capsys, tty: bool) -> str:  # noqa: ANN001
    progress = _Progress(enabled=True, tty=tty)
    for event in EVENTS:
        progress(event)
    progress.finish()
    return capsys.readouterr().err


def test_progress_in_a_log_is_one_line_per_finished_step(capsys) -> None:
    err = _run(capsys, tty=False)
    assert "\r" not in err
    lines = err.splitlines()
    assert len(lines) == 4  # the finished move, the DT's verdict, the failed move, the end
    assert lines[0].startswith("t=   25.0s  plans=  1  action (move place1 placeholder2)")
    assert lines[2].endswith("(move place2 place3) failed")
    assert "found" in lines[3]


def test_progress_on_a_terminal_rewrites_one_line(capsys) -> None:
    err = _run(capsys, tty=True)
    assert err.count("\r") == 6 and err.endswith("\n") and err.count("\n") == 1
