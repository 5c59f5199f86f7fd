"""The end-to-end bench's pure parts: instance lists, the plan `avs plan` prints, and the
summary (coverage, validity counted, the median ours/FD ratio over instances both solved).
Nothing here runs FD or times anything."""

import argparse

import pytest

from bench.e2e_bench import parse_instances, parse_plan, stopped_by, summarize, summary_lines


def test_instance_lists_take_ranges_and_lists():
    assert parse_instances("1-3") == (1, 2, 3)
    assert parse_instances("2") == (2,)
    assert parse_instances("4-5, 1,2,2") == (1, 2, 4, 5)


@pytest.mark.parametrize("text", ["", "a", "3-1", "0-2", "1-x", ","])
def test_bad_instance_lists_are_refused(text):
    with pytest.raises(argparse.ArgumentTypeError):
        parse_instances(text)


def test_the_printed_plan_is_read_without_the_comment_lines():
    out = ("(pick-up b)\n(stack b a)\n; stopped by: timeout (the best plan found so far)\n"
           "; cost: 2\n; probability: 1\n")
    assert parse_plan(out) == (("pick-up", ("b",)), ("stack", ("b", "a")))
    assert stopped_by(out) == "timeout"
    assert stopped_by("(noop)\n; cost: 1\n") is None


def _row(label, ours_s, fd_s, ours="solved", fd="solved", ours_valid=True, fd_valid=True,
         stop=None):
    return {"label": label, "ours_s": ours_s, "fd_s": fd_s, "ours_status": ours,
            "fd_status": fd, "ours_stopped_by": stop,
            "ours_valid": ours_valid if ours == "solved" else None,
            "fd_valid": fd_valid if fd == "solved" else None}


def test_the_ratio_is_over_the_instances_both_solved_and_above_one_means_slower():
    rows = [_row("a/1", 1.0, 2.0), _row("a/2", 3.0, 1.0), _row("a/3", 2.0, 1.0),
            _row("b/1", 35.0, 0.5, ours="killed"), _row("b/2", 4.0, 35.0, fd="timeout")]
    s = summarize(rows)
    assert (s["instances"], s["ours_solved"], s["fd_solved"], s["both"]) == (5, 4, 4, 3)
    assert s["median_ratio"] == 2.0 and s["slower"] == 2  # ratios 0.5, 3, 2
    assert (s["median_ours_s"], s["median_fd_s"]) == (2.0, 1.0)
    assert s["fd_only"] == ["b/1"] and s["ours_only"] == ["b/2"]
    lines = summary_lines(s)
    assert lines[0] == ("-- coverage: ours 4/5, lama-first 4/5; FD solved and we did not: b/1; "
                        "we solved and FD did not: b/2")
    assert lines[1].endswith("ours 4/4, FD 4/4: all valid")
    assert "median over the 3 both solved: 2.00x (above 1: ours slower; slower on 2 of 3)" \
        in lines[2]


def test_a_plan_is_valid_only_when_the_validator_said_so():
    rows = [_row("a/1", 1.0, 1.0, ours_valid=False), _row("a/2", 1.0, 1.0, fd_valid=None)]
    s = summarize(rows)
    assert not s["all_valid"] and s["invalid"] == ["a/1 (ours)", "a/2 (fd)"]
    assert (s["ours_valid"], s["fd_valid"]) == (1, 1)
    assert "NOT ALL VALID: a/1 (ours), a/2 (fd)" in summary_lines(s)[1]


def test_nothing_solved_by_both_gives_no_ratio_and_timeouts_are_counted():
    s = summarize([_row("a/1", 30.5, 35.0, fd="timeout", stop="timeout")])
    assert s["median_ratio"] is None and s["ours_stopped_by_timeout"] == 1
    lines = summary_lines(s)
    assert "median over the 0 both solved: -" in lines[2]
    assert lines[3].startswith("-- ours returned its best plan at --timeout on 1")


def test_missing_values_keep_the_table_columns():
    from bench.e2e_bench import _fmt

    assert _fmt(None, "7.2f") == "      -" and _fmt(1.5, "7.2f") == "   1.50"
    assert _fmt(None, "g") == "-"
