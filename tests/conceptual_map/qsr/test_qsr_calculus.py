"""Eq. 1 (ternary point calculus) checked by hand, and relations classified in the desk scene."""

import math

import numpy as np
import pytest

from bench import qsr_scene
from conceptual_map.qsr import Landmark, classify, load_qsr, relative_angle, relative_radius
from conceptual_map.qsr.calculus import nearest_direction, place_objects, virtual_robot


@pytest.mark.parametrize(
    ("obj", "expected"),
    [((2.0, 0.0), 0.0),  # beyond the landmark: behind
     ((1.0, 1.0), math.pi / 2),  # the robot's left
     ((0.5, 0.0), math.pi),  # between robot and landmark: front
     ((1.0, -1.0), 3 * math.pi / 2)],  # the robot's right
)  # fmt: skip
def test_relative_angle_on_the_x_axis(obj, expected):
    assert relative_angle((0.0, 0.0), (1.0, 0.0), obj) == pytest.approx(expected)


def test_relative_angle_with_a_turned_reference_axis():
    # robot (0, 0), landmark (0, 2): the axis points along +y (90 degrees)
    assert relative_angle((0, 0), (0, 2), (-1, 2)) == pytest.approx(math.pi / 2)  # left is -x
    # object at (1, 3): atan2(1, 1) - pi/2 = -pi/4, wrapped to 7pi/4
    assert relative_angle((0, 0), (0, 2), (1, 3)) == pytest.approx(7 * math.pi / 4)
    # robot (3, 1), landmark (1, 1): axis along -x; object (1, 0) is on the robot's left
    assert relative_angle((3, 1), (1, 1), (1, 0)) == pytest.approx(math.pi / 2)


def test_relative_radius_and_the_imagined_robot():
    assert relative_radius((0, 0), (2, 0), (2, 1)) == pytest.approx(0.5)
    monitor = Landmark("monitor", 1.5, 5.7, -math.pi / 2)
    np.testing.assert_allclose(virtual_robot(monitor, 1.0), [1.5, 4.7], atol=1e-12)


def test_place_objects_inverts_eq_1():
    rng = np.random.default_rng(3)
    robot, relatum = np.array([0.3, -0.2]), rng.uniform(-2, 2, (50, 2))
    angle, dist = rng.uniform(0, 2 * math.pi, 50), rng.uniform(0.1, 1.0, 50)
    points = place_objects(robot, relatum, angle, dist)
    np.testing.assert_allclose(relative_angle(robot, relatum, points), angle, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(points - relatum, axis=1), dist, atol=1e-12)


def test_nearest_direction_wraps_round():
    means = {"behind": 0.0, "left": math.pi / 2, "front": math.pi, "right": 3 * math.pi / 2}
    assert nearest_direction(math.radians(350), means) == "behind"
    assert nearest_direction(math.radians(100), means) == "left"
    assert nearest_direction(math.radians(250), means) == "right"


def test_classify_matches_the_desk_scene():
    knowledge = load_qsr()
    poses = qsr_scene.object_poses()

    def landmark(name):
        label, x, y, _, yaw = poses[name]
        return knowledge.landmark(label, x, y, yaw, name)

    def step(obj, lm):
        s = classify(poses[obj][1:3], landmark(lm), knowledge)
        return s.relations

    assert step("cup1", "keyboard1") == ("right", "close")  # +x on a desk facing -y
    assert step("cup3", "keyboard3") == ("left", "close")
    assert step("keyboard1", "monitor1") == ("front", "close")
    assert step("keyboard4", "monitor4") == ("front", "close")  # the desk turned by -90 deg
    assert step("laptop2", "keyboard2") == ("left", "distant")
    assert step("monitor1", "keyboard1") == ("behind", "close")
