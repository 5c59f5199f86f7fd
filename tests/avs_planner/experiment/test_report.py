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


def test_wilson_intervals_stay_in_0_1_around_the_estimate():
    """In floating point the ends at 0/n and n/n came out a rounding error off (10/10 gave an
    upper end of 0.9999999999999999), and the report's error bars went negative."""
    for n in range(1, 401):
        for k in {0, 1, n - 1, n}:
            interval = wilson(k, n)
            assert 0.0 <= interval.low <= interval.estimate <= interval.high <= 1.0, (k, n)
    assert wilson(10, 10).high == 1.0 and wilson(13, 13).high == 1.0
    assert wilson(0, 3).low == 0.0 and wilson(0, 7).low == 0.0


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


def _write(path: Path, rows: list[dict]) -> None:
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


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
    _write(path, rows)


STAMP = "_Campaign fixture, run 2026-11-23 to 2026-11-24, commit abc1234._"
META = {"name": "fixture", "runs": 23, "invocations": [
    {"started": "2026-11-23T22:00:00", "finished": "2026-11-24T08:00:00", "commit": "abc1234",
     "dirty": False, "backend": "local", "workers": 2, "ran": 23, "failed": 1,
     "wall_s": 61.5}]}


def test_the_report_from_a_fixture_table(tmp_path):
    _fixture(tmp_path / "results.csv")
    (tmp_path / "campaign.json").write_text(json.dumps(META))
    report = build_report(tmp_path, tmp_path / "out" / "report.md").read_text()
    lines = report.splitlines()
    a = next(line for line in lines if line.startswith("| A | 11 |"))
    b = next(line for line in lines if line.startswith("| B | 12 |"))
    # found, correct give-up, false reports, timeouts (2 sim-budget), wall cuts, failed
    assert "| 0.80 [0.49, 0.94] (8/10) | 1.00 [0.21, 1.00] (1/1) | 0 | 2 | 0 | 0 |" in a
    assert "| 105 / 109 |" in a  # median and p90 of 100..109 and 200
    assert "| 0.300 / 0.300 | 1.000 / 1.000 |" in a
    assert "(5/11) | 0.00 [0.00, 0.79] (0/1) | 1 | 5 | 0 | 1 |" in b  # a false report, a crash
    paired = next(line for line in lines if line.startswith("| all | A | B | 11"))
    assert "| all | A | B | 11 | +0.36 [" in paired  # (9 - 5) / 11
    # both found in seeds 0-4: ratios (100 + k) / (110 + k), median 102 / 112
    assert paired.endswith("| 5 | 0.91 [0.91, 0.91] (n 5) | 5/5 | 0 | -- |")
    targets = next(line for line in lines if line.startswith("| all | A | 8/10 = 80%"))
    assert targets == ("| all | A | 8/10 = 80% [49, 94] | 1/1 = 100% [21, 100] | 0 | 2 | 0 | "
                       "0 | · | 0.91 [0.91, 0.91] (n 5) | · | -- |")
    assert "| all | B | 5/11 = 45% [21, 72] | 0/1 = 0% [0, 79] | 1 | 5 | 0 | 1 | 1.10 [" \
        in report
    assert "| group g2 | A | -- | 1/1 = 100% [21, 100] |" in report  # two groups: a slice each
    assert "| robot " not in report  # one robot: no robot slices
    assert "| g2 | 1.00 [0.21, 1.00] (1/1) | 0.00 [0.00, 0.79] (0/1) |" in report
    assert "| B-99 | crashed | episode process killed by signal 9 |" in report
    assert "median scheduling overhead per episode (wall time outside the episode): 0.100 s" \
        in report
    assert "Beside the paper" not in report and "Map quality" not in report
    assert report.startswith("# Campaign report: fixture\n")
    assert ("- runs recorded: 23 of 23; completed 22, cut by the wall-clock budget 0, "
            "crashed/timed out/failed 1") in report
    assert ("- `avs experiment run` finished 2026-11-24T08:00:00 at commit abc1234: 23 "
            "episodes (1 failed) on local x2 in 61.5 s") in report
    # every table says which campaign, when and at which commit
    sections = [line for line in lines if line.startswith("## ")]
    tables = [s for s in sections if s not in ("## Plots", "## Failed and wall-cut runs")]
    assert len(tables) == 5 and report.count(STAMP) == len(tables)
    assert f"- {STAMP[1:-1]}" in report
    for png in ("report-sim-time.png", "report-success.png"):
        assert f"]({png})" in report
        assert (tmp_path / "out" / png).read_bytes()[:4] == b"\x89PNG"


def test_the_seed003_table_sets_our_numbers_beside_the_papers(tmp_path):
    rows = [_row("switching", k, scenario=s, group=s, run_id=f"{s}-{k}", plans=10 + k,
                 outcome="found" if s == "a" else "gave_up",
                 expected="found" if s == "a" else "gave_up",
                 success="true" if s == "a" else "", sim_time_s=300,
                 correct_give_up="" if s == "a" else "true") for s in "ac" for k in range(5)]
    _write(tmp_path / "results.csv", rows)
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    assert ('## Beside the paper: Göbelbecker et al., "A Planning Approach to Active Visual '
            'Search in Large Environments", Fig. 3 a-f') in report
    assert "seed 003" not in report.lower() and "seed paper" not in report
    assert ("| a | found | 5/0/0 / 0 (of 5) | 12 [10-14] | 0.300 [0.300-0.300] | 2 [2-2] | "
            "1.000 [1.000-1.000] |") in report
    assert "| c | gave_up | 0/5/0 / 0 (of 5) |" in report


def test_a_directory_without_results_is_refused(tmp_path):
    with pytest.raises(CampaignError, match="no results.csv; run `avs experiment run` first"):
        build_report(tmp_path, tmp_path / "report.md")


def test_a_report_where_every_run_succeeds_renders_with_its_plots(tmp_path, capsys):
    """100% in a group: the Wilson upper end was a hair under 1.0 and matplotlib refused the
    negative error bar ('yerr' must not contain negative values)."""
    from avs_planner.cli import main

    rows = [_row(s, k, group=g, run_id=f"{s}-{g}-{k}", outcome="found", success="true",
                 sim_time_s=100 + k) for s in ("A", "B") for g in ("g1", "g2")
            for k in range(10)]
    _write(tmp_path / "results.csv", rows)
    assert main(["experiment", "report", str(tmp_path)]) == 0, capsys.readouterr().err
    report = (tmp_path / "report.md").read_text()
    assert "| g1 | 1.00 [0.72, 1.00] (10/10) | 1.00 [0.72, 1.00] (10/10) |" in report
    for png in ("report-sim-time.png", "report-success.png"):
        assert f"]({png})" in report
        assert (tmp_path / png).read_bytes()[:4] == b"\x89PNG"


def _styles_and_robots() -> list[dict]:
    """switching finds in half the time of exhaustive and a quarter of most-likely-room, and
    gives up in twice exhaustive's time; most-likely-room never gives up (its sim budget)."""
    rows = []
    for robot in ("pioneer", "pr2"):
        for group in ("gen-office", "gen-lab"):
            for k in range(5):
                world = f"{group}-{k}"
                for strategy, factor, give_up in (("switching", 1, 300),
                                                  ("exhaustive", 2, 150),
                                                  ("most-likely-room", 4, None)):
                    common = {"group": group, "world": world, "robot": robot}
                    rows.append(_row(strategy, 0, **common, run_id=f"{strategy}-{world}-cup-"
                                     f"{robot}", outcome="found", success="true",
                                     sim_time_s=factor * (50 + k)))
                    rows.append(_row(strategy, 0, **common, run_id=f"{strategy}-{world}-"
                                     f"banana-{robot}", target="banana", expected="gave_up",
                                     outcome="gave_up" if give_up else "timeout",
                                     correct_give_up="true" if give_up else "false",
                                     sim_time_s=give_up or 1200))
    return rows


def test_paired_time_ratios_by_robot_and_world_group(tmp_path):
    _write(tmp_path / "results.csv", _styles_and_robots())
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    assert ("| all | switching | 20/20 = 100% [84, 100] | 20/20 = 100% [84, 100] | 0 | 0 | 0 "
            "| 0 | · | 0.50 [0.50, 0.50] (n 20) | 0.25 [0.25, 0.25] (n 20) | · | "
            "2.00 [2.00, 2.00] (n 20) | -- |") in report
    assert ("| all | most-likely-room | 20/20 = 100% [84, 100] | 0/20 = 0% [0, 16] | 0 | 20 | "
            "0 | 0 | 4.00 [4.00, 4.00] (n 20) | 2.00 [2.00, 2.00] (n 20) | · | -- | -- | · |"
            ) in report
    for part in ("robot pioneer", "robot pr2", "group gen-lab", "group gen-office"):
        assert (f"| {part} | switching | 10/10 = 100% [72, 100] | 10/10 = 100% [72, 100] | 0 "
                f"| 0 | 0 | 0 | · | 0.50 [0.50, 0.50] (n 10) |") in report
        assert (f"| {part} | switching | exhaustive | 20 | +0.00 [+0.00, +0.00] | 10 | 0.50 "
                f"[0.50, 0.50] (n 10) | 10/10 | 10 | 2.00 [2.00, 2.00] (n 10) |") in report
    assert "| all | switching | most-likely-room | 40 | +0.50 [" in report


def test_paired_time_ratio_intervals_are_seeded(tmp_path):
    rows = _styles_and_robots()
    for k, r in enumerate(rows):  # ratios that differ from pair to pair
        if r["strategy"] == "switching":
            r["sim_time_s"] *= 1 + (k * 7919 % 13) / 10
    _write(tmp_path / "results.csv", rows)
    first = build_report(tmp_path, tmp_path / "one.md").read_text()
    from avs_planner.experiment import report_cells

    report_cells.median_interval.cache_clear()
    again = build_report(tmp_path, tmp_path / "two.md").read_text()
    assert first.replace("one-", "two-") == again
    line = next(x for x in first.splitlines() if x.startswith("| all | switching | exhaus"))
    low, high = (float(v) for v in line.split("|")[7].split("[")[1].split("]")[0].split(","))
    median = float(line.split("|")[7].split("[")[0])
    assert low < median < high


def test_wall_cut_runs_are_counted_apart_and_left_out_of_rates_and_pairs(tmp_path):
    rows = [_row(s, k, outcome="found", success="true", sim_time_s=100 + k)
            for s in ("A", "B") for k in range(4)]
    rows[0].update(status="wall_cut", outcome="timeout", success="", error="cut by the "
                   "wall-clock budget: wall time budget 300 s spent")
    rows[1].update(outcome="timeout", success="false",  # recorded before wall_cut existed
                   reason="wall time budget 300 s spent")
    rows[2].update(outcome="timeout", success="false", reason="simulated time budget 1200 s "
                   "spent")
    _write(tmp_path / "results.csv", rows)
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    # A: seeds 0 and 1 cut (left out), seed 2 a timeout of the strategy, seed 3 found
    assert "| A | 4 | 0.50 [0.09, 0.91] (1/2) | -- | 0 | 1 | 2 | 0 |" in report
    assert "| all | A | B | 2 | -0.50 [" in report  # seeds 2 and 3 only
    assert "cut by the wall-clock budget 2, crashed/timed out/failed 0" in report
    assert "| A-0 | wall_cut | cut by the wall-clock budget: wall time budget 300 s spent |" \
        in report
    assert "| A-1 | wall_cut | wall time budget 300 s spent |" in report


def test_map_quality_and_dt_verdicts_when_summaries_carry_them(tmp_path):
    rows = [_row("switching", 0, outcome="found", success="true", sim_time_s=90,
                 map_rooms_true=6, map_rooms_matched=5, map_merges=1, map_splits=0,
                 map_category_accuracy=0.75, map_entered_area_m2=40, dt_confirmed=1,
                 map_entered_rooms=4, map_entered_matched=4,
                 dt_rejected=2),
            _row("switching", 1, outcome="found", success="true", sim_time_s=95, dt_calls=0,
                 map_rooms_true=6, map_rooms_matched=4, map_merges=0, map_splits=1,
                 map_category_accuracy=0.5, map_entered_area_m2=20, dt_confirmed=0,
                 map_entered_rooms=2, map_entered_matched=1,
                 dt_rejected=0),
            _row("switching", 2, outcome="found", success="true", sim_time_s=99),  # old
            _row("exhaustive", 0, outcome="found", success="true", sim_time_s=120,
                 dt_calls=0)]
    _write(tmp_path / "results.csv", rows)
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    assert ("| all | switching | 2 | 9/12 = 75% | 5/6 = 83% | 1 | 1 | 67% (over 60 m²) | 30.0 |"
            in report)
    assert "| all | exhaustive |" not in report.split("## Map quality")[1].split("##")[0]
    assert "| switching | g1 | 3 | 2/3 (67%) | 4 | 2.0 [2] | 1 | 2 |" in report
    assert "| exhaustive | g1 |" not in report  # never called the DT


def test_the_stamp_names_mixed_commits_and_unknown_ones(tmp_path):
    rows = [_row("A", k, outcome="found", success="true", sim_time_s=100, commit=c)
            for k, c in enumerate(["abc1234", "def5678+dirty", "unknown"])]
    _write(tmp_path / "results.csv", rows)
    report = build_report(tmp_path, tmp_path / "report.md").read_text()
    assert ("commit abc1234, def5678+dirty, unknown (mixed: results.csv's `commit` column "
            "says which run is which) (+dirty: tracked files differed from the commit)"
            ) in report
    assert "run on an unrecorded date" in report
