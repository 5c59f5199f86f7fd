"""Sensors: laser distances, detection rates, occlusion, false positives, seeding, places."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sim.camera import DetectorConfig, sample_points, visible_fraction
from sim.errors import SimError
from sim.place_classifier import PlaceClassifier
from sim.scene import World, load_world

DATA = Path(__file__).parent / "data"
TILT_DOWN = math.radians(-20.0)  # brings the table top and the cabinet's floor into view


def _sensor_room(seed: int = 0, **detector: float) -> World:
    world = load_world(DATA / "sensor_room.yaml", seed=seed)
    world.robot.set_head(0.0, TILT_DOWN)
    world.robot.detector_config = DetectorConfig(**detector)
    return world


def _thing(world: World, name: str):
    return next(t for t in world.detectables if t.name == name)


def test_laser_sees_the_walls_at_the_right_distances() -> None:
    with _sensor_room() as world:
        scan = world.robot.scan()
        x, y, yaw = scan.pose
        assert (x, y, yaw) == pytest.approx((1.12, 2.0, 0.0))
        half = world.spec.wall_thickness / 2
        expected = {0.0: 4.0 - half - x, math.pi / 2: 4.0 - half - y, -math.pi / 2: y - half}
        for angle, distance in expected.items():
            i = int(np.argmin(np.abs(scan.angles - angle)))
            assert scan.ranges[i] == pytest.approx(distance, abs=0.05)
        assert scan.angles.shape == scan.ranges.shape == (241,)
        assert scan.angles[0] == pytest.approx(-math.radians(120.0))


def test_laser_reports_inf_beyond_range() -> None:
    with load_world("office") as world:  # corridor is 12 m long, the laser reaches 5.6 m
        scan = world.robot.scan()
        i = int(np.argmin(np.abs(scan.angles)))
        assert scan.ranges[i] == np.inf
        assert np.isfinite(scan.points()).all()


def test_depth_rays_hit_the_floor_and_walls() -> None:
    with _sensor_room() as world:
        frame = world.robot.depth(size=(16, 12))
        assert frame.directions.shape == (192, 3) and frame.ranges.shape == (192,)
        assert np.allclose(np.linalg.norm(frame.directions, axis=1), 1.0)
        points = frame.points()
        assert len(points) > 150
        assert -0.1 < points[:, 2].min() < 0.05  # the floor
        assert points[:, 0].max() == pytest.approx(3.95, abs=0.05)  # the wall at x = 4


def test_object_in_plain_view_is_detected_at_one_minus_fn() -> None:
    trials = 400
    with _sensor_room(seed=3) as world:
        view = world.robot.camera_view()
        assert visible_fraction(world.client, view, _thing(world, "cup1")) > 0.9
        hits = sum("cup" in world.robot.detect(["cup"]).labels() for _ in range(trials))
    # fp_rate 0.05 can add a phantom cup; P(cup reported) = 1 - 0.2 * 0.95 = 0.81
    assert abs(hits / trials - 0.81) < 0.06


def test_true_detection_carries_truth_view_and_noisy_position() -> None:
    with _sensor_room(fn_rate=0.0, fp_rate=0.0) as world:
        (cup,) = world.robot.detect(["cup"])
        assert cup.truth_name == "cup1"
        assert cup.position == pytest.approx([3.0, 1.5, 0.8], abs=0.2)
        assert not np.array_equal(cup.position, [3.0, 1.5, 0.8])
        assert 0.0 < cup.confidence < 1.0
        assert cup.view.hfov == pytest.approx(math.radians(60.0))
        assert cup.time == world.robot.clock


def test_object_inside_a_cabinet_is_not_detected() -> None:
    with _sensor_room(fn_rate=0.0, fp_rate=0.0) as world:
        view = world.robot.camera_view()
        stapler = _thing(world, "stapler1")
        assert view.contains(sample_points(stapler)).all()  # in the frustum, yet hidden
        assert visible_fraction(world.client, view, stapler) == 0.0
        assert all(len(world.robot.detect(["stapler"])) == 0 for _ in range(20))
        assert "cabinet" in world.robot.detect().labels()


def test_object_behind_a_wall_is_not_detected_until_the_robot_walks_round() -> None:
    with _sensor_room(fn_rate=0.0, fp_rate=0.0) as world:
        robot = world.robot
        book = _thing(world, "book1")
        assert robot.camera_view().contains(sample_points(book)).all()
        assert all(len(robot.detect(["book"])) == 0 for _ in range(20))
        world.set_door_open(0, True)
        robot.move_along([(1.0, 0.6), (5.5, 0.6), (5.5, 1.2)])
        robot.turn_to(math.pi / 2 + 0.3)
        assert robot.detect(["book"]).labels() == ["book"]


def test_false_positives_occur_at_the_configured_rate() -> None:
    trials = 1000
    with _sensor_room(seed=5, fp_rate=0.05) as world:
        frames = [world.robot.detect(["banana"]) for _ in range(trials)]
    phantoms = [d for f in frames for d in f]
    assert all(d.truth_name is None and d.label == "banana" for d in phantoms)
    assert abs(len(phantoms) / trials - 0.05) < 0.025


def test_false_positive_rate_is_configurable() -> None:
    with _sensor_room(seed=5, fp_rate=0.5) as world:
        phantoms = sum(len(world.robot.detect(["banana"])) for _ in range(400))
    assert abs(phantoms / 400 - 0.5) < 0.08


def test_sensors_are_deterministic_by_seed() -> None:
    def run(seed: int) -> tuple[np.ndarray, list[str]]:
        with _sensor_room(seed=seed) as world:
            ranges = world.robot.scan().ranges
            labels = [label for _ in range(30) for label in world.robot.detect().labels()]
            return ranges, labels

    a, b, c = run(1), run(1), run(2)
    assert np.array_equal(a[0], b[0]) and a[1] == b[1]
    assert not np.array_equal(a[0], c[0])


def test_what_the_camera_reports_of_a_label_does_not_depend_on_the_other_labels_asked() -> None:
    """Asking for more labels (furniture as well as the target) leaves the target's misses,
    noise and phantoms frame for frame as they were: two runs differ only in what they ask."""
    def cups(extra: list[str]) -> list[tuple[str, tuple[float, ...]]]:
        with _sensor_room(seed=3, fp_rate=0.3) as world:
            frames = [world.robot.detect(["cup", "banana", *extra]) for _ in range(40)]
        return [(d.label, tuple(np.round(d.position, 9))) for f in frames
                for d in f.detections if d.label in ("cup", "banana")]

    alone, among = cups([]), cups(["table", "chair", "stapler", "book"])
    assert alone == among
    assert {label for label, _ in alone} == {"cup", "banana"}  # hits and phantoms both


def test_detector_config_rejects_bad_rates() -> None:
    with pytest.raises(SimError, match="fn_rate"):
        DetectorConfig(fn_rate=1.5)


def test_place_classifier_follows_its_confusion_matrix() -> None:
    with load_world("office", seed=2) as world:
        robot = world.robot
        assert robot.room() == "corridor"
        seen = [robot.classify_place() for _ in range(600)]
    share = sum(o.observed == "corridor" for o in seen) / len(seen)
    assert abs(share - 0.7) < 0.06
    kitchen = next(o for o in seen if o.observed == "kitchen")
    # over the classifier's whole vocabulary (six categories), not the office's three
    expected = {c: 0.06 for c in ("corridor", "office", "meeting_room", "living_room",
                                  "bathroom")}
    assert kitchen.likelihood == pytest.approx({**expected, "kitchen": 0.7})


def test_place_classifier_with_a_custom_matrix() -> None:
    confusion = {
        "kitchen": {"kitchen": 0.9, "office": 0.1},
        "office": {"kitchen": 0.4, "office": 0.6},
    }
    classifier = PlaceClassifier(confusion)
    obs = classifier.observe("office", np.random.default_rng(0), 0.0)
    assert obs.likelihood == confusion_column(confusion, obs.observed)
    with pytest.raises(SimError, match="sum to 1"):
        PlaceClassifier({"a": {"a": 0.5, "b": 0.4}, "b": {"a": 0.0, "b": 1.0}})
    with pytest.raises(SimError, match="no confusion row for category 'corridor'"):
        classifier.observe("corridor", np.random.default_rng(0), 0.0)


def confusion_column(confusion: dict[str, dict[str, float]], seen: str) -> dict[str, float]:
    return {true: row[seen] for true, row in confusion.items()}


def test_min_visible_fraction_decides_on_a_half_seen_object() -> None:
    with _sensor_room(fn_rate=0.0, fp_rate=0.0) as world:
        robot = world.robot
        robot.set_head(0.0, 0.0)
        robot.turn_to(-0.76)  # the cup (bearing -0.245 rad) sits on the left edge of the image
        view = robot.camera_view()
        fraction = visible_fraction(world.client, view, _thing(world, "cup1"))
        assert 0.2 < fraction < 0.9
        robot.detector_config = DetectorConfig(fn_rate=0.0, fp_rate=0.0,
                                                min_visible_fraction=fraction + 0.05)
        assert "cup" not in robot.detect(["cup"]).labels()
        robot.detector_config = DetectorConfig(fn_rate=0.0, fp_rate=0.0,
                                                min_visible_fraction=fraction - 0.05)
        assert "cup" in robot.detect(["cup"]).labels()


def test_a_single_label_string_is_one_label() -> None:
    with _sensor_room(fn_rate=0.0, fp_rate=0.0) as world:
        assert world.robot.detect("cup").queried == ("cup",)
