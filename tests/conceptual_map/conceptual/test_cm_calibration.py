"""The placeholder model calibrated by how this building's placeholders ended."""

import math

import numpy as np
import pytest

from conceptual_map.conceptual import NO_NEW_ROOM, ConceptualMap, PlaceholderEvidence
from conceptual_map.conceptual.calibration import (
    PlaceholderCalibration,
    calibrated_weights,
    map_offset,
    new_room_probability,
)
from conceptual_map.conceptual.placeholders import hypothesis_weights, predict
from conceptual_map.knowledge import load_knowledge

OPEN = PlaceholderEvidence("corr", open_space_m2=20.0, p_door=0.0)
DOOR = PlaceholderEvidence("corr", open_space_m2=20.0, p_door=0.9)


def _corridor(apply: bool = True) -> ConceptualMap:
    cmap = ConceptualMap()
    cmap.calibration.apply = apply
    for i in range(3):
        cmap.add_place(f"c{i}", "corr")
        cmap.observe_property(f"c{i}", "shape", "elongated")
    cmap.add_placeholder("open", "corr", open_space_m2=20.0, p_door=0.0)
    cmap.add_placeholder("door", "corr", open_space_m2=20.0, p_door=0.9)
    return cmap


def test_with_nothing_recorded_the_model_is_as_written():
    cmap = _corridor()
    knowledge = cmap.knowledge
    for pid, evidence in (("open", OPEN), ("door", DOOR)):
        expected = predict(knowledge, cmap.room_marginal("corr"), evidence)
        got = cmap.placeholder_prediction(pid)
        assert dict(got.any_room) == pytest.approx(dict(expected.any_room), abs=0.0)
        assert got.no_new_room == expected.no_new_room


@pytest.mark.parametrize("offset", [-3.0, -0.5, 0.7, 2.5])
def test_calibrated_weights_move_only_the_new_room_share(offset):
    weights = hypothesis_weights(load_knowledge().placeholder, OPEN)
    moved = calibrated_weights(weights, offset)
    q, q_new = new_room_probability(weights), new_room_probability(moved)
    assert sum(moved.values()) == pytest.approx(1.0)
    assert math.log(q_new / (1 - q_new)) - math.log(q / (1 - q)) == pytest.approx(offset)
    rooms = [h for h in weights if h.new_rooms > 0]
    none = [h for h in weights if h.new_rooms == 0]
    for group in (rooms, none):  # shares within each group are kept
        a, b = sum(weights[h] for h in group), sum(moved[h] for h in group)
        for h in group:
            assert moved[h] / b == pytest.approx(weights[h] / a)


def test_the_offset_is_the_posterior_mode():
    rows = [(1.5, 0), (1.5, 0), (0.5, 1), (2.0, 0), (-0.3, 0)]
    b = map_offset(rows, prior_sd=1.0)

    def log_post(x: float) -> float:
        terms = (math.log(1 / (1 + math.exp(-(z + x))) if y else 1 - 1 / (1 + math.exp(-(z + x))))
                 for z, y in rows)
        return sum(terms) - x * x / 2

    grid = np.linspace(-6, 6, 120001)
    best = grid[int(np.argmax([log_post(x) for x in grid]))]
    assert b == pytest.approx(best, abs=2e-4)
    assert map_offset([]) == 0.0


def test_placeholders_that_led_nowhere_lower_the_others_of_their_kind_only():
    cmap = _corridor()
    open_before = 1 - cmap.placeholder_category("open")[NO_NEW_ROOM]
    door_before = 1 - cmap.placeholder_category("door")[NO_NEW_ROOM]
    beyond_before = cmap.p_beyond_placeholder("cup", "open")
    for _ in range(6):
        cmap.observe_placeholder_outcome(OPEN, False)
    open_after = 1 - cmap.placeholder_category("open")[NO_NEW_ROOM]
    assert open_after < open_before - 0.3
    assert 1 - cmap.placeholder_category("door")[NO_NEW_ROOM] == door_before
    assert cmap.p_beyond_placeholder("cup", "open") < beyond_before
    category = cmap.placeholder_category("open")
    assert sum(category[c] for c in cmap.knowledge.categories) >= open_after - 1e-9


def test_placeholders_that_led_to_rooms_raise_the_others():
    cmap = ConceptualMap()
    cmap.calibration.apply = True
    cmap.add_place("c0", "corr")
    weak = PlaceholderEvidence("corr", open_space_m2=2.0, p_door=0.0)
    cmap.add_placeholder("ph", "corr", open_space_m2=2.0, p_door=0.0)
    before = 1 - cmap.placeholder_category("ph")[NO_NEW_ROOM]
    for _ in range(5):
        cmap.observe_placeholder_outcome(weak, True)
    assert 1 - cmap.placeholder_category("ph")[NO_NEW_ROOM] > before + 0.2


def test_many_outcomes_bring_the_model_to_the_buildings_rate():
    calibration = PlaceholderCalibration(load_knowledge().placeholder, apply=True)
    rng = np.random.default_rng(3)
    for y in rng.random(400) < 0.3:
        calibration.record(OPEN, bool(y))
    rate = np.mean([y for _, y in calibration.outcomes["open"]])
    assert new_room_probability(calibration.weights(OPEN)) == pytest.approx(rate, abs=0.02)
    summary = calibration.summary()
    assert summary["open"]["resolved"] == 400 and "door" not in summary


def test_outcomes_are_measured_but_change_nothing_unless_applied():
    cmap = _corridor(apply=False)
    before = cmap.placeholder_category("open")
    for _ in range(6):
        cmap.observe_placeholder_outcome(OPEN, False)
    assert cmap.placeholder_category("open") == before
    summary = cmap.calibration.summary()["open"]
    assert summary["resolved"] == 6 and summary["new_room"] == 0
    assert summary["predicted"] == pytest.approx(
        new_room_probability(hypothesis_weights(cmap.knowledge.placeholder, OPEN)), abs=1e-4)
    assert summary["offset"] < -1.0
