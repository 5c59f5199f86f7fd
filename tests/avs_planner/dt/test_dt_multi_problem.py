"""Multi-label problem input: every bad input is refused with a message naming the culprit."""

import pytest

from avs_planner.dt import (
    DetectorModel,
    DtInputError,
    DTRewards,
    LabelTarget,
    MultiLabelProblem,
    SearchMode,
    TravelCosts,
    ViewCone,
)

CONES = (ViewCone("a", (1, 0, 0), 0.0), ViewCone("b", (2, 0, 0), 0.0),
         ViewCone("c", (3, 0, 0), 0.0))
TRAVEL = TravelCosts.from_lists([1, 2, 3], [[0, 1, 2], [1, 0, 1], [2, 1, 0]])


def _problem(*targets, **kwargs):
    return MultiLabelProblem(CONES, targets, TRAVEL, **kwargs)


def test_no_labels():
    with pytest.raises(DtInputError, match="no labels to search for"):
        _problem()


def test_duplicate_labels():
    with pytest.raises(DtInputError, match="label 1: duplicate label 'cup'"):
        _problem(LabelTarget("cup", (0.2, 0.2, 0.2)), LabelTarget("cup", (0.1, 0.1, 0.1)))


def test_empty_label_name():
    with pytest.raises(DtInputError, match="label 0: the label name is empty"):
        _problem(LabelTarget("", (0.2, 0.2, 0.2)))


def test_probabilities_over_one_name_the_label():
    with pytest.raises(DtInputError, match=r"label 'book': view cone probabilities sum to 1.2 > 1"):
        _problem(LabelTarget("cup", (0.2, 0.2, 0.2)), LabelTarget("book", (0.5, 0.4, 0.3)))


def test_probability_out_of_range_names_the_label_and_cone():
    with pytest.raises(DtInputError, match=r"label 'cup': view cone 1 \(b\): probability -0.1"):
        _problem(LabelTarget("cup", (0.2, -0.1, 0.2)))


def test_probabilities_must_cover_every_cone():
    with pytest.raises(DtInputError, match="label 'cup': 2 probabilities for 3 view cones"):
        _problem(LabelTarget("cup", (0.2, 0.2)))


def test_unknown_mode_lists_the_modes():
    with pytest.raises(DtInputError, match=r"search mode 'some' is not one of \['all', 'any'\]"):
        _problem(LabelTarget("cup", (0.2, 0.2, 0.2)), mode="some")


def test_negative_horizon_and_sensing_cost():
    with pytest.raises(DtInputError, match="horizon -1"):
        _problem(LabelTarget("cup", (0.2, 0.2, 0.2)), horizon=-1)
    with pytest.raises(DtInputError, match="sensing_cost"):
        _problem(LabelTarget("cup", (0.2, 0.2, 0.2)), sensing_cost=-1.0)


def test_each_label_is_a_single_label_problem_over_the_shared_cones():
    cup = LabelTarget("cup", (0.5, 0.0, 0.0), DetectorModel(0.1, 0.02), DTRewards(50.0, 80.0))
    book = LabelTarget("book", (0.0, 0.0, 0.3))
    problem = _problem(cup, book, sensing_cost=2.0, mode="any")
    assert problem.mode is SearchMode.ANY and problem.labels == ("cup", "book")
    assert problem.single(0).prior == pytest.approx((0.5, 0.0, 0.0, 0.5))
    assert problem.single(1).prior == pytest.approx((0.0, 0.0, 0.3, 0.7))
    assert problem.single(0).detector == cup.detector and problem.single(0).rewards == cup.rewards
    assert all(s.sensing_cost == 2.0 and s.travel == TRAVEL for s in problem.singles)
    assert problem.relevant_cones((0, 1)) == (0, 2) and problem.relevant_cones((1,)) == (2,)
    assert problem.horizon == 2 * 2 + 4  # as the single-label default, over cones any label needs
    assert all(s.horizon == problem.horizon for s in problem.singles)
    assert problem.index("book") == 1
    with pytest.raises(DtInputError, match="unknown label 'mug'"):
        problem.index("mug")
