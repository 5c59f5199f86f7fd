"""The factored multi-label belief: Bayes updates by hand, one look updates every open label,
a claim touches one label only, and pomdp-py's exact update of the joint agrees."""

import random
from itertools import product

import pomdp_py
import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    NOTHING,
    DetectorModel,
    DtSessionError,
    LabelTarget,
    MultiLabelProblem,
    MultiObservation,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.domain import NOWHERE, START
from avs_planner.dt.multi import MultiLabelBelief, MultiLabelState
from avs_planner.dt.multi.domain import OPEN, confirm_label, look_at, move_to, reject_label
from avs_planner.dt.multi.models import MultiLabelObservationModel, MultiLabelTransitionModel

CONES = (ViewCone("a", (1, 0, 0), 0.0), ViewCone("b", (2, 0, 0), 0.0))


@pytest.fixture
def problem():
    return MultiLabelProblem(
        CONES,
        (LabelTarget("cup", (0.5, 0.3), DetectorModel(false_negative=0.2, false_positive=0.05)),
         LabelTarget("book", (0.1, 0.6), DetectorModel(false_negative=0.1, false_positive=0.1))),
        TravelCosts.from_lists([1, 2], [[0, 1], [1, 0]]))


def _seen(cup, book):
    return MultiObservation((cup, book))


def test_one_look_updates_each_label_by_its_own_detector(problem):
    belief = MultiLabelBelief.initial(problem).after(move_to(0), None, problem)
    belief = belief.after(look_at(0), _seen(DETECTED, NOT_DETECTED), problem)
    # cup seen: P(hit | in a) = 0.8, P(hit | elsewhere) = 0.05
    #   weights 0.5 * 0.8 = 0.4, 0.3 * 0.05 = 0.015, nowhere 0.2 * 0.05 = 0.01; total 0.425
    assert belief.probs(0) == pytest.approx((0.4 / 0.425, 0.015 / 0.425, 0.01 / 0.425))
    assert belief.probs(0) == pytest.approx((0.941176, 0.035294, 0.023529), abs=1e-6)
    # book missed: P(miss | in a) = 0.1, P(miss | elsewhere) = 0.9
    #   weights 0.1 * 0.1 = 0.01, 0.6 * 0.9 = 0.54, nowhere 0.3 * 0.9 = 0.27; total 0.82
    assert belief.probs(1) == pytest.approx((0.01 / 0.82, 0.54 / 0.82, 0.27 / 0.82))
    assert belief.probs(1) == pytest.approx((0.012195, 0.658537, 0.329268), abs=1e-6)
    assert belief.detected(0) and not belief.detected(1)
    assert [f.hits for f in belief.factors] == [(1, 0), (0, 0)]
    assert [f.misses for f in belief.factors] == [(0, 0), (1, 0)]


def test_second_look_then_hand_numbers(problem):
    belief = MultiLabelBelief.initial(problem).after(move_to(1), None, problem)
    belief = belief.after(look_at(1), _seen(NOT_DETECTED, DETECTED), problem)
    belief = belief.after(look_at(1), _seen(NOT_DETECTED, NOT_DETECTED), problem)
    # cup missed twice at b: in b 0.3 * 0.2^2 = 0.012, elsewhere 0.95^2 = 0.9025
    cup = [0.5 * 0.9025, 0.012, 0.2 * 0.9025]
    assert belief.probs(0) == pytest.approx(tuple(w / sum(cup) for w in cup))
    # book hit then missed at b: in b 0.6 * 0.9 * 0.1 = 0.054, elsewhere 0.1 * 0.9 = 0.09
    book = [0.1 * 0.09, 0.054, 0.3 * 0.09]
    assert belief.probs(1) == pytest.approx(tuple(w / sum(book) for w in book))
    assert not belief.detected(1)


def test_look_outcomes_are_products_of_the_labels_detection_odds(problem):
    belief = MultiLabelBelief.initial(problem).after(move_to(0), None, problem)
    branches = belief.outcomes(look_at(0), problem)
    cup_hit = 0.5 * 0.8 + 0.5 * 0.05  # 0.425
    book_hit = 0.1 * 0.9 + 0.9 * 0.1  # 0.18
    expected = {(True, True): cup_hit * book_hit, (True, False): cup_hit * (1 - book_hit),
                (False, True): (1 - cup_hit) * book_hit,
                (False, False): (1 - cup_hit) * (1 - book_hit)}
    got = {(b.detected(0), b.detected(1)): p for p, b in branches}
    assert got == pytest.approx(expected)


def test_a_claim_never_changes_another_labels_belief(problem):
    belief = MultiLabelBelief.initial(problem).after(move_to(0), None, problem)
    belief = belief.after(look_at(0), _seen(DETECTED, DETECTED), problem)
    confirmed = belief.after(confirm_label("cup", 0), None, problem)
    assert confirmed.factors[1] == belief.factors[1]
    assert confirmed.claims == (0, OPEN) and confirmed.robot == 0
    rejected = belief.after(reject_label("book"), None, problem)
    assert rejected.factors[0] == belief.factors[0] and rejected.claims == (OPEN, NOWHERE)


def test_a_decided_label_is_no_longer_updated_by_looks(problem):
    belief = MultiLabelBelief.initial(problem).after(reject_label("book"), None, problem)
    book = belief.factors[1]
    belief = belief.after(move_to(0), None, problem)
    belief = belief.after(look_at(0), _seen(NOT_DETECTED, NOTHING), problem)
    assert belief.factors[1] == book and belief.probs(0)[0] < 0.5


def test_update_errors_name_the_label(problem):
    belief = MultiLabelBelief.initial(problem).after(move_to(0), None, problem)
    with pytest.raises(DtSessionError, match="needs a detection result for label 'book'"):
        belief.after(look_at(0), _seen(DETECTED, NOTHING), problem)
    with pytest.raises(DtSessionError, match="only a label just detected"):
        belief.after(confirm_label("cup", 0), None, problem)
    with pytest.raises(DtSessionError, match="unknown label 'mug'"):
        belief.after(reject_label("mug"), None, problem)
    once = belief.after(reject_label("cup"), None, problem)
    with pytest.raises(DtSessionError, match="'cup' is already decided"):
        once.after(reject_label("cup"), None, problem)


def test_impossible_observation_is_an_error_for_that_label():
    problem = MultiLabelProblem(
        CONES, (LabelTarget("cup", (0.0, 0.0), DetectorModel(0.2, 0.0)),),
        TravelCosts.from_lists([1, 2], [[0, 1], [1, 0]]))
    belief = MultiLabelBelief.initial(problem).after(move_to(0), None, problem)
    with pytest.raises(DtSessionError, match="label 'cup'.*impossible"):
        belief.after(look_at(0), MultiObservation((DETECTED,)), problem)


def _joint_histogram(problem):
    """The joint prior over both labels' locations (the test's oracle; the package never
    builds it)."""
    locations = [*range(problem.n), NOWHERE]
    joint = {}
    for targets in product(locations, repeat=problem.k):
        p = 1.0
        for i, t in enumerate(targets):
            p *= problem.single(i).prior[t if t != NOWHERE else problem.n]
        if p > 0.0:
            joint[MultiLabelState.start(START, targets)] = p
    return pomdp_py.Histogram(joint)


def _marginal(histogram, i, n):
    probs = [0.0] * (n + 1)
    for state in histogram:
        t = state.targets[i]
        probs[t if t != NOWHERE else n] += histogram[state]
    return probs


def test_pomdp_py_joint_update_equals_the_product_of_the_factors(problem):
    transition = MultiLabelTransitionModel(problem, random.Random(0))
    observation_model = MultiLabelObservationModel()
    histogram = _joint_histogram(problem)
    belief = MultiLabelBelief.initial(problem)
    steps = [(move_to(0), MultiObservation.nothing(2)), (look_at(0), _seen(DETECTED, NOT_DETECTED)),
             (move_to(1), MultiObservation.nothing(2)), (look_at(1), _seen(NOT_DETECTED, DETECTED))]
    for action, seen in steps:
        successors = {s for state in histogram for s, _ in transition.successors(state, action)}
        histogram = pomdp_py.update_histogram_belief(histogram, action, seen, observation_model,
                                                     transition, next_state_space=successors)
        belief = belief.after(action, seen, problem)
        for i in range(problem.k):
            assert _marginal(histogram, i, problem.n) == pytest.approx(belief.probs(i))
    for state in histogram:  # the joint posterior stays the product of the marginals
        if histogram[state] > 0.0:
            t = [x if x != NOWHERE else problem.n for x in state.targets]
            assert histogram[state] == pytest.approx(belief.probs(0)[t[0]] * belief.probs(1)[t[1]])
