"""Input checking of the DT problem: every error names what is wrong."""

import math

import pytest

from avs_planner.dt import DetectorModel, DtInputError, DTProblem, DTRewards, TravelCosts, ViewCone
from avs_planner.dt.domain import START


def _cones(*probs):
    return tuple(ViewCone(f"c{i}", (float(i), 0.0, 0.0), p) for i, p in enumerate(probs))


def test_prior_appends_not_here_mass():
    problem = DTProblem(_cones(0.5, 0.3), TravelCosts.from_lists([1, 2], [[0, 1], [1, 0]]))
    assert problem.prior == pytest.approx((0.5, 0.3, 0.2))
    assert problem.relevant_cones == (0, 1)


def test_probabilities_summing_over_one_are_rejected():
    with pytest.raises(DtInputError, match="sum to 1.2"):
        DTProblem(_cones(0.6, 0.6), TravelCosts.from_lists([1, 1], [[0, 1], [1, 0]]))


def test_bad_cone_probability_names_the_cone():
    with pytest.raises(DtInputError, match=r"view cone 1 \(c1\): probability 1.5"):
        DTProblem(_cones(0.1, 1.5), TravelCosts.from_lists([1, 1], [[0, 1], [1, 0]]))


def test_duplicate_ids_are_rejected():
    cones = (ViewCone("a", (0, 0, 0), 0.1), ViewCone("a", (1, 0, 0), 0.1))
    with pytest.raises(DtInputError, match="duplicate id 'a'"):
        DTProblem(cones, TravelCosts.from_lists([1, 1], [[0, 1], [1, 0]]))


@pytest.mark.parametrize(
    ("start", "matrix", "message"),
    [
        ([1], [[0]], "cover 1 cones"),
        ([1, -2], [[0, 1], [1, 0]], "travel from start to cone 1"),
        ([1, 1], [[0, 1]], "1 rows, expected 2"),
        ([1, 1], [[0, 1], [1]], "row 1 has 1 entries"),
        ([1, 1], [[0, math.inf], [1, 0]], "travel from cone 0 to cone 1"),
    ],
)
def test_bad_travel_costs_name_the_entry(start, matrix, message):
    with pytest.raises(DtInputError, match=message):
        DTProblem(_cones(0.2, 0.2), TravelCosts.from_lists(start, matrix))


def test_detector_and_rewards_are_checked():
    with pytest.raises(DtInputError, match="false_negative"):
        DetectorModel(false_negative=1.2)
    with pytest.raises(DtInputError, match="carries no evidence"):
        DetectorModel(false_negative=0.6, false_positive=0.5)
    with pytest.raises(DtInputError, match="miss_penalty"):
        DTRewards(miss_penalty=-1)


def test_travel_cost_from_start_and_between_cones():
    problem = DTProblem(_cones(0.2, 0.2), TravelCosts.from_lists([3, 4], [[0, 7], [8, 0]]))
    assert problem.travel_cost(START, 1) == 4
    assert problem.travel_cost(0, 1) == 7
    assert problem.travel_cost(1, 1) == 0


def test_costs_from_poses_are_driving_plus_turning_time():
    cones = (ViewCone("a", (3.0, 4.0, math.pi / 2), 0.5),)
    costs = TravelCosts.from_poses((0.0, 0.0, 0.0), cones, speed=0.5, turn_speed=1.0)
    assert costs.from_start[0] == pytest.approx(5.0 / 0.5 + math.pi / 2)


def test_metric_flag_detects_shortcuts():
    metric = DTProblem(_cones(0.3, 0.3, 0.3),
                       TravelCosts.from_lists([1, 2, 3], [[0, 1, 2], [1, 0, 1], [2, 1, 0]]))
    shortcut = DTProblem(_cones(0.3, 0.3, 0.3),
                         TravelCosts.from_lists([1, 2, 3], [[0, 1, 5], [1, 0, 1], [5, 1, 0]]))
    assert metric.metric and not shortcut.metric


def test_default_horizon_counts_relevant_cones():
    problem = DTProblem(_cones(0.2, 0.0, 0.3), TravelCosts.from_lists([1] * 3, [[0] * 3] * 3))
    assert problem.horizon == 2 * 2 + 4
