"""Statistics and the Markdown report, checked on a hand-made results table."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from avs_planner.experiment import CampaignError
from avs_planner.experiment.report import build_report
from avs_planner.experiment.results import COLUMNS
from avs_planner.experiment.stats import bootstrap, median, quantile, wilson


@pytest.mark.parametrize(("k", "n", "low", "high"), [
    (5, 10, 0.2366, 0.7634),  # the textbook value
    (8, 10, 0.4902, 0.9433),
    (17, 20, 0.6396, 0.9476),
    (0, 10, 0.0, 0.2775),  # z^2 / (n + z^2)
    (10, 10, 0.7225, 1.0),
])
def test_wilson_intervals(k, n, low, high):
    interval = wilson(k, n)
    assert interval.estimate == pytest.approx(k / n)
    assert (interval.low, interval.high) == pytest.approx((low, high), abs=1e-4)


def test_no_runs_no_rate():
    assert wilson(0, 0) is None and median([]) is None and quantile([], 0.5) is None


def test_quantiles_interpolate_like_numpy():
    assert quantile([4, 1, 3, 2], 0.9) == pytest.approx(3.7)
    assert quantile([4, 1, 3, 2], 0.5) == median([1, 2, 3, 4]) == 2.5
    assert quantile([7], 0.9) == 7


def test_bootstrap_is_seeded_and_brackets_the_mean():
    values = [float(v) for v in (1, 0, 1, 1, 0, 1, 1, 1, 0, 1)]
    first, again = bootstrap(values), bootstrap(values)
    assert first == again
    assert first.estimate == pytest.approx(0.7)
    assert 0.3 < first.low < 0.7 < first.high <= 1.0
    same = bootstrap([-10.0] * 5)
    assert (same.estimate, same.low, same.high) == (-10.0, -10.0, -10.0)


def _row(strategy: str, seed: int, **values) -> dict:
    base = {"run_id": f"{strategy}-{seed}", "scenario": "", "world": "w", "group": "g1",
            "target": "cup", "expected": "found", "strategy": strategy, "robot": "",
            "seed": seed, "status": "ok", "backend": "local", "plans": 4,
            "cp_s_per_plan": 0.3, "dt_s_per_action": 1.0, "distance_m": 10.0,
            "episode_s": 5.0, "wall_s": 5.1, "overhead_s": 0.1, "false_report": "false",
            "dt_calls": 2}
    return {**base, **values}


def _fixture(path: Path) -> None:
    """A finds 8 of 10 cups (100+k s), B 5 of 10 (110+k s); on an absent banana A gives up
    and B reports a wrong object; B crashed once more."""
    rows = []
    for k in range(10):
        rows.append(_row("A", k, outcome="found" if k < 8 else "timeout",
                         success="true" if k < 8 else "false", sim_time_s=100 + k))
        rows.append(_row("B", k, outcome="found" if k < 5 else "timeout",
                         success="true" if k < 5 else "false", sim_time_s=110 + k))
    rows.append(_row("A", 0, target="banana", expected="gave_up", outcome="gave_up",
                     correct_give_up="true", sim_time_s=200, group="g2"))
    rows.append(_row("B", 0, target="banana", expected="gave_up", outcome="found",
                     correct_give_up="false", false_report="true", sim_time_s=50, group="g2"))
    rows.append(_row("B", 99, status="crashed", error="episode process killed by signal 9",
                     overhead_s="", sim_time_s="", plans="", distance_m="",
                     cp_s_per_plan="", dt_s_per_action=""))
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def test_the_report_from_a_fixture_table(tmp_path):
    _fixture(tmp_path / "results.csv")
    (tmp_path / "campaign.json").write_text(json.dumps({
        "name": "fixture", "runs": 23, "invocations": [
            {"finished": "2026-11-24T08:00:00", "backend": "local", "workers": 2, "ran": 23,
             "failed": 1, "wall_s": 61.5}]}))
    report = build_report(tmp_path, tmp_path / "out" / "report.md").read_text()
    lines = report.splitlines()
    a = next(line for line in lines if line.startswith("| A | 11 |"))
    b = next(line for line in lines if line.startswith("| B | 12 |"))
    assert "| 0.80 [0.49, 0.94] (8/10) | 1.00 [0.21, 1.00] (1/1) | 0 | 0 |" in a
    assert "| 105 / 109 |" in a  # median and p90 of 100..109 and 200
    assert "| 0.300 / 0.300 | 1.000 / 1.000 |" in a
    assert "(5/11) | 0.00 [0.00, 0.79] (0/1) | 1 | 1 |" in b  # a false report, a crash
    paired = next(line for line in lines if line.startswith("| A | B | 11"))
    assert "| A | B | 11 | +0.36 [" in paired  # (9 - 5) / 11
    assert paired.endswith("| 5 | -10.0 [-10.0, -10.0] | 5/5 |")
    assert "| g2 | 1.00 [0.21, 1.00] (1/1) | 0.00 [0.00, 0.79] (0/1) |" in report
    assert "| B-99 | crashed | episode process killed by signal 9 |" in report
    assert "median scheduling overhead per episode (wall time outside the episode): 0.100 s" \
        in report
    assert "Beside the seed paper" not in report
    assert report.startswith("# Campaign report: fixture\n")
    assert "- runs recorded: 23 of 23; completed 22, crashed/timed out/failed 1" in report
    assert ("- `avs experiment run` finished 2026-11-24T08:00:00: 23 episodes (1 failed) on "
            "local x2 in 61.5 s") in report
    for png in ("report-sim-time.png", "report-success.png"):
        assert f"]({png})" in report
        assert (tmp_path / "out" / png).read_bytes()[:4] == b"\x89PNG"


def test_the_seed003_table_sets_our_numbers_beside_the_papers(tmp_path):
    rows = [_row("switching", k, scenario=s, group=s, run_id=f"{s}-{k}", plans=10 + k,
                 outcome="found" if s == "a" else "gave_up",
                 expected="found" if s == "a" else "gave_up",
                 success="true" if s == "a" else "", sim_time_s=300,
                 correct_give_up="" if s == "a" else "true") for s in "ac" for k in range(5)]
    with (tmp_path / "results.csv").open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    assert ("| a | found | 5/0/0 / 0 (of 5) | 12 [10-14] | 0.300 [0.300-0.300] | 2 [2-2] | "
            "1.000 [1.000-1.000] |") in report
    assert "| c | gave_up | 0/5/0 / 0 (of 5) |" in report


def test_a_directory_without_results_is_refused(tmp_path):
    with pytest.raises(CampaignError, match="no results.csv; run `avs experiment run` first"):
        build_report(tmp_path, tmp_path / "report.md")
