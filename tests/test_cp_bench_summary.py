"""The CP bench's office-scale line: issue 3's target on the problems it names."""

from bench.cp_bench import office_scale


def _row(label, ours_ms, fd_ms, status="solved"):
    return {"label": label, "ours_s": ours_ms / 1e3, "fd_s": fd_ms / 1e3, "status": status}


def test_office_scale_takes_the_seed_and_20_place_problems_only():
    rows = [_row("avs/corridor", 10, 900), _row("avs/room3", 4, 800),
            _row("gen/avs-p20-h5-r4-l8-s0", 22, 3000), _row("gen/avs-p20-h5-r4-l8-s1", 30, 3000),
            _row("gen/avs-p8-h2-r2-l4-s0", 1, 500)]  # 8 places: not office scale
    # ratios 90, 200, 136.4, 100
    line = office_scale(rows)
    assert line.startswith("-- office scale, issue 3's target (4: seed problems + 20-place): "
                           "median ours 16.0 ms cold (target <= 20)")
    assert "median FD/ours 118.2x (target >= 5x), solved 4/4: met" in line
    assert line.endswith("slowest gen/avs-p20-h5-r4-l8-s1 30.0 ms")


def test_office_scale_says_missed_for_a_slow_median_or_an_unsolved_problem():
    slow = [_row("avs/a", 25, 900), _row("gen/avs-p20-h5-r4-l8-s0", 21, 900)]
    assert ": MISSED;" in office_scale(slow)
    unsolved = [_row("avs/a", 5, 900), _row("avs/b", 5, 900, status="timeout")]
    assert "solved 1/2: MISSED;" in office_scale(unsolved)


def test_office_scale_is_silent_without_such_problems():
    assert office_scale([_row("ipc/blocks/instance-1", 3, 300)]) is None
