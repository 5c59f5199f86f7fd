"""Learning: a found object's relations to nearby landmarks add to the description counts."""

import math

import pytest

from conceptual_map.qsr import build_mixture, learn_from_observation, load_qsr, parse_descriptions


def _knowledge():
    items = [{"target": "cup", "relations": ["right", "close"], "of": "keyboard", "count": 1},
             {"target": "cup", "relations": ["left", "close"], "of": "keyboard", "count": 1}]
    return parse_descriptions(items, load_qsr())


def _weights(knowledge, keyboard):
    mixture = build_mixture(knowledge, "cup", [keyboard], samples=50).mixture
    return {s.split("(")[0]: w for s, w in zip(mixture.sources, mixture.weights, strict=True)}


def test_finding_a_cup_right_of_a_keyboard_moves_weight_to_right():
    knowledge = _knowledge()
    # yaw pi/2 with the front at -90 deg: faces +x, so the viewer looks along -x, right is +y
    keyboard = knowledge.landmark("keyboard", 2.0, 3.0, math.pi / 2)
    before = _weights(knowledge, keyboard)
    update = learn_from_observation(knowledge, "cup", (2.0, 3.4), [keyboard])
    assert [d.text() for d in update.credited] == ["right(cup, keyboard) & close(cup, keyboard)"]
    after = _weights(update.knowledge, keyboard)
    assert before["right"] == pytest.approx(0.5)
    assert after["right"] == pytest.approx(2 / 3) and after["left"] == pytest.approx(1 / 3)
    assert knowledge.descriptions[0].count == 1  # the old knowledge is unchanged


def test_an_unseen_relation_becomes_a_new_description():
    knowledge = _knowledge()
    keyboard = knowledge.landmark("keyboard", 0.0, 0.0, math.pi / 2)  # faces +x
    monitor = knowledge.landmark("monitor", 0.0, 0.5, math.pi / 2)
    update = learn_from_observation(knowledge, "cup", (0.3, 0.0), [keyboard, monitor])
    texts = {d.text(): d.count for d in update.knowledge.descriptions}
    assert texts["front(cup, keyboard) & close(cup, keyboard)"] == 1
    # from the monitor: 121 deg (nearest to left's 90), 0.58 m > 0.5 m
    assert texts["left(cup, monitor) & distant(cup, monitor)"] == 1
    assert len(update.knowledge.descriptions) == 4


def test_far_landmarks_do_not_learn():
    knowledge = _knowledge()
    keyboard = knowledge.landmark("keyboard", 0.0, 0.0, 0.0)
    update = learn_from_observation(knowledge, "cup", (3.0, 0.0), [keyboard])
    assert update.credited == () and update.knowledge.descriptions == knowledge.descriptions
