"""The CP bench's summary lines: coverage with failures counted at the limit, and the
office-scale (speed-up over FD) and building-scale (planning time) targets, met or missed."""

from bench.cp_report import building_scale, office_scale, summary


def _row(label, ours_ms, fd_own_ms, fd_ms=None, status="solved", fd_solved=True, read_ms=None):
    return {"label": label, "ours_s": ours_ms / 1e3, "ours_read_s": (read_ms or ours_ms) / 1e3,
            "fd_own_s": fd_own_ms / 1e3, "fd_s": (fd_ms or fd_own_ms * 2) / 1e3,
            "status": status, "fd_solved": fd_solved}


def test_office_scale_takes_the_seed_and_20_place_problems_only():
    rows = [_row("avs/corridor", 10, 900, read_ms=100), _row("avs/room3", 4, 800, read_ms=80),
            _row("gen/avs-p20-h5-r4-l8-s0", 22, 3000, read_ms=300),
            _row("gen/avs-p20-h5-r4-l8-s1", 30, 3000, read_ms=300),
            _row("gen/avs-p8-h2-r2-l4-s0", 1, 500)]  # 8 places: not office scale
    line = office_scale(rows)  # own/ours: 90, 200, 136.4, 100 -> 118.2
    assert line.startswith("-- office scale (4: paper problems + 20-place): median ours+read "
                           "200.0 ms, FD own/ours (planning) 118.2x (target >= 5x)")
    assert "FD own/ours+read 10.0x" in line and "solved 4/4: met" in line
    assert line.endswith("slowest gen/avs-p20-h5-r4-l8-s0 300.0 ms")


def test_office_scale_says_missed_for_a_slow_ratio_or_an_unsolved_problem():
    slow = [_row("avs/a", 250, 900), _row("gen/avs-p20-h5-r4-l8-s0", 210, 900)]
    assert ": MISSED;" in office_scale(slow)
    unsolved = [_row("avs/a", 5, 900), _row("avs/b", 5, 900, status="timeout")]
    assert "solved 1/2: MISSED;" in office_scale(unsolved)


def test_office_scale_is_silent_without_such_problems():
    assert office_scale([_row("ipc/blocks/instance-1", 3, 300)]) is None


def test_coverage_counts_failures_and_names_what_fd_solved_and_we_did_not():
    rows = [_row("a/1", 10, 100), _row("a/2", 60000, 200, status="timeout"),
            _row("a/3", 10, 60000, fd_solved=False)]
    lines = summary(rows, probabilistic=False)
    assert lines[0] == "-- coverage: ours 2/3, FD 2/3; FD solved and we did not: a/2"
    assert "ours 10.0 ms" in lines[1]  # median of 10, 60000 (the limit), 10


def test_building_scale_against_its_targets():
    rows = [_row("gen/avs-p80-h16-r16-l8-s0", 40, 100), _row("gen/avs-p160-h32-r32-l8-s0",
                                                             300, 100)]
    line = building_scale(rows)
    assert "80 places 40.0 ms (target <= 50: met)" in line
    assert "160 places 300.0 ms (target <= 200: MISSED)" in line


def test_rows_saved_as_json_lines_are_summarized(tmp_path, capsys):
    """`--jsonl` keeps the rows of a long run that is stopped; `--summarize` prints them."""
    import json
    import math

    from bench.cp_bench import summarize

    rows = [_row("blocks/instance-1", 10, 100), _row("tetris/instance-5", 60000, 200,
                                                     status="timeout")]
    rows[0].update(ours_cost=6.0, fd_cost=6.0, ours_valid=True)
    rows[1].update(warm_s=math.nan)
    path = tmp_path / "rows.jsonl"
    path.write_text("".join(json.dumps({"kind": "ipc", **r}) + "\n" for r in rows))
    summarize(path)
    out = capsys.readouterr().out
    assert "IPC instances (deterministic): 2 rows from" in out
    assert "-- coverage: ours 1/2, FD 2/2; FD solved and we did not: tetris/instance-5" in out
    assert "plan cost, ours/FD, median over the 1 both solved: 1.000" in out


def test_ipc_instances_can_be_picked_by_domain_and_number() -> None:
    import pytest

    from bench.cp_bench import ipc_cases
    from tests.ipc import require_ipc

    require_ipc()
    picked = ipc_cases(False, domains=("blocks", "tetris"), numbers=(2, 3))
    assert [c.label for c in picked] == ["blocks/instance-2", "blocks/instance-3",
                                         "tetris/instance-2", "tetris/instance-3"]
    with pytest.raises(SystemExit, match="no IPC domain nosuch"):
        ipc_cases(False, domains=("nosuch",))
