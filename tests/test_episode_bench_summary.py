"""The episode bench's last line: every CP call of every episode against the 20 ms target."""

from bench.episode_bench import _print_cp_calls


def test_cp_calls_line_counts_every_call(capsys):
    rows = [{"cp_time_s": [0.004, 0.010, 0.030]}, {"cp_time_s": [0.002]}, {"cp_time_s": []}]
    _print_cp_calls(rows)
    line = capsys.readouterr().out.strip()
    assert line.startswith("-- CP calls in 3 episodes: 4, median 7.0 ms")
    assert "p90 30.0 ms, max 30.0 ms, 75% within 20 ms" in line
    assert line.endswith("first plans median 3.0 ms")


def test_cp_calls_line_is_silent_without_calls(capsys):
    _print_cp_calls([{"cp_time_s": []}])
    assert capsys.readouterr().out == ""
