"""bench/qsr_experiment.py's analysis lines: where the prior densities lie in the two scenes,
and the ordering check of Table II."""

import pytest

from bench.qsr_experiment import density_at_cups, ordering, with_failures


def test_the_desk_scene_gives_both_informed_methods_the_same_mass_on_cup_supports():
    desks = density_at_cups("qsr_desks_a")
    assert desks["uniform_support"] == pytest.approx(0.75)  # 3 of the 4 equal desks
    assert desks["qsr_support"] == pytest.approx(0.75, abs=0.02)
    kitchen = density_at_cups("qsr_kitchen_a")
    assert kitchen["uniform_support"] < 0.35 < 0.7 < kitchen["qsr_support"]
    for scene in (desks, kitchen):
        assert scene["qsr_near"] > 2.0 * scene["uniform_near"]


def _row(poses, time, ci=0.1):  # noqa: ANN001, ANN202
    return {"poses": poses, "time": time, "poses_ci": ci, "time_ci": ci}


def test_ordering_reports_holds_fails_and_overlap():
    table = {"qsr/A": _row(1.0, 10.0), "supporting-planes/A": _row(2.0, 9.0),
             "random/A": _row(3.0, 30.0)}
    poses, time = ordering(table)
    assert "holds; qsr/supporting-planes intervals disjoint, supporting-planes/random " \
        "intervals disjoint" in poses
    assert "FAILS" in time
    table["supporting-planes/A"] = _row(1.05, 20.0)
    assert "holds; qsr/supporting-planes intervals overlap, supporting-planes/random " \
        "intervals disjoint" in ordering(table)[0]
    table["random/A"] = _row(None, None)
    assert "found nothing" in ordering(table)[0]


def test_failures_count_at_the_abort_time():
    runs = [{"outcome": "found", "correct": True, "search_time_s": 20.0, "poses": 1},
            {"outcome": "gave_up", "correct": False, "search_time_s": 121.5, "poses": 6},
            {"outcome": "found", "correct": False, "search_time_s": 30.0, "poses": 2}]
    time_s, poses = with_failures(runs)
    assert time_s == pytest.approx((20.0 + 121.5 + 120.0) / 3)
    assert poses == pytest.approx(3.0)
