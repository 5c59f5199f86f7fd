"""Transition times: the time model by hand, and the clustered table against exact A* times."""

import math

import numpy as np
import pytest

from avs_planner.flap.errors import FlapError
from avs_planner.flap.sampling import ViewPose, ViewSampler
from avs_planner.flap.transitions import build_table, exact_time, path_time, sensing_time
from bench.flap_scene import PIONEER_BODY, PR2_BODY, Scene


def test_time_model_by_hand() -> None:
    body = PIONEER_BODY  # differential: turns onto each segment
    seconds, heading = path_time(body, (0.0, 0.0, 0.0), [(0.0, 1.0), (1.0, 1.0)])
    assert heading == pytest.approx(0.0)
    assert seconds == pytest.approx((math.pi / 2) / 1.0 + 1 / 0.5 + (math.pi / 2) / 1.0 + 1 / 0.5)
    seconds, _ = path_time(PR2_BODY, (0.0, 0.0, 0.0), [(0.0, 1.0), (1.0, 1.0)])
    assert seconds == pytest.approx(2 / 0.5)  # omni base: no turning


def test_exact_time_in_place_is_joints_and_sensing(scene: Scene) -> None:
    a = ViewPose(3.0, 2.5, 0.0, 0.0, 0.0, 0.0)
    b = ViewPose(3.0, 2.5, 0.5, 0.3, 0.0, -0.4)
    body = PR2_BODY
    expected = 0.5 / body.angular_speed + 0.3 / body.torso_speed + 0.4 / body.tilt_speed
    assert exact_time(body, scene.grid, a, b) == pytest.approx(expected + sensing_time(body))


@pytest.mark.parametrize("body, mean_bound, worst_bound",
                         [(PR2_BODY, 0.03, 0.15), (PIONEER_BODY, 0.10, 0.35)],
                         ids=["pr2", "pioneer"])  # fmt: skip
def test_table_stays_close_to_exact_path_times(scene, belief, body, mean_bound, worst_bound):  # noqa: ANN001, ANN201
    views = ViewSampler(scene.voxels, scene.grid, body, belief).sample(150, seed=2)
    start = ViewPose(*scene.start, 0.0, 0.0, 0.0)
    poses = [v.pose for v in views]
    table = build_table(body, scene.grid, start, poses, clusters=40)
    assert table.kept.size == len(poses)
    rng = np.random.default_rng(4)
    errors = []
    for i, j in rng.integers(table.kept.size, size=(40, 2)):
        if i != j:
            exact = exact_time(body, scene.grid, poses[i], poses[j])
            errors.append(abs(table.times[i, j] - exact) / exact)
    for j in range(0, len(poses), 15):
        exact = exact_time(body, scene.grid, start, poses[j])
        errors.append(abs(table.start[j] - exact) / exact)
    assert np.mean(errors) <= mean_bound and np.max(errors) <= worst_bound
    assert np.all(table.times[~np.eye(len(poses), dtype=bool)] >= sensing_time(body))


def test_unreachable_views_are_left_out(scene: Scene) -> None:
    inside = ViewPose(3.0, 2.5, 0.0, 0.0, 0.0, 0.0)
    on_table = ViewPose(1.8, 1.4, 0.0, 0.0, 0.0, 0.0)  # inside a table: no path there
    table = build_table(PR2_BODY, scene.grid, inside, [on_table, inside], clusters=5)
    assert table.kept.tolist() == [1]
    with pytest.raises(FlapError):
        build_table(PR2_BODY, scene.grid, inside, [on_table], clusters=5)
