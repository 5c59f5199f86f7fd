"""View selection (eq. 2, Algorithm 1): cone and frustum tests by hand, poses, the three methods."""

import math

import numpy as np
import pytest

from avs_planner.body import JointRange, RobotBody
from avs_planner.errors import AvsError
from avs_planner.qsr import (
    ScoredPose,
    SelectionStatus,
    ViewMethod,
    ViewOptions,
    ViewSelectionError,
    best_rate,
    cone_half_angle,
    in_frustums,
    in_view_cones,
    pose_rates,
    pose_times,
    rank_frustums,
    sample_poses,
    score_cones,
    score_poses,
    select_view,
)
from bench import qsr_scene
from conceptual_map.metric import OccupancyGrid
from conceptual_map.qsr import build_mixture, extract_supporting_planes, load_qsr

BODY = RobotBody(
    name="pioneer", footprint_radius=0.25, holonomic=False, camera_height=1.4,
    torso=JointRange(0.0, 0.0), pan=JointRange(-2.77, 2.77), tilt=JointRange(-0.82, 0.54),
    hfov=math.radians(60), vfov=math.radians(45), depth_range=5.0, detect_range=4.0,
    laser_range=5.6, linear_speed=0.5, angular_speed=1.0, torso_speed=1.0, pan_speed=1.0,
    tilt_speed=1.0, scan_time=0.1, sensing_time=0.5,
)  # fmt: skip


def _open_grid(size=(10.0, 10.0)) -> OccupancyGrid:
    grid = OccupancyGrid((0.0, 0.0), size, 0.05)
    grid.logodds[...] = grid.model.clamp_min
    grid.logodds[[0, -1], :] = grid.model.clamp_max
    grid.logodds[:, [0, -1]] = grid.model.clamp_max
    grid._touch()
    return grid


def _patch(x0, y0, x1, y1, z=0.75, step=0.05) -> np.ndarray:
    xs, ys = np.meshgrid(np.arange(x0, x1, step), np.arange(y0, y1, step), indexing="ij")
    return np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, z)])


def test_view_cone_membership_by_hand():
    poses = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, math.pi]])
    points = np.array([[1.0, 0.0], [1.0, 1.0], [5.0, 0.0], [-1.0, 0.1], [1.0, 0.55]])
    mask = in_view_cones(poses, points, math.radians(30), 4.0)
    # 45 deg off axis is outside a 30 deg half-angle; 5 m is beyond range; 28.8 deg is in
    assert mask.tolist() == [[True, False, False, False, True], [False, False, False, True, False]]
    side = np.array([[math.cos(math.radians(95)), math.sin(math.radians(95))]])
    assert in_view_cones(poses[:1], side, math.radians(100), 4.0).tolist() == [[True]]
    assert in_view_cones(poses[:1], side, math.radians(90), 4.0).tolist() == [[False]]


def test_frustum_membership_by_hand():
    camera = np.array([0.0, 0.0, 1.4])
    points = np.array([[2.0, 0.0, 1.4], [2.0, 0.0, 0.5], [2.0, 1.0, 1.4], [-2.0, 0.0, 1.4]])
    fov = (math.radians(60), math.radians(45))
    level = in_frustums(camera, np.array([0.0]), np.array([0.0]), points, fov, 4.0)[0]
    # 0.9 m below at 2 m is 24.2 deg down (> 22.5); 1 m aside is 26.6 deg (< 30)
    assert level.tolist() == [True, False, True, False]
    # tilted 17.2 deg down: the level points are 17.2 deg above the axis, the low one 7 deg below
    down = in_frustums(camera, np.array([0.0]), np.array([-0.3]), points, fov, 4.0)[0]
    assert down.tolist() == [True, True, True, False]
    steep = in_frustums(camera, np.array([0.0]), np.array([-0.5]), points, fov, 4.0)[0]
    assert steep.tolist() == [False, True, False, False]  # level points 28.6 deg above
    back = in_frustums(camera, np.array([math.pi]), np.array([0.0]), points, fov, 4.0)[0]
    assert back.tolist() == [False, False, False, True]


def test_score_cones_is_eq_2():
    points = np.vstack([_patch(4.0, 8.0, 5.0, 8.5), _patch(4.0, 1.5, 5.0, 2.0)])
    density = np.where(points[:, 1] > 5.0, 1.0, 0.0)
    density /= density.sum()
    poses = np.array([[4.5, 5.0, math.pi / 2], [4.5, 5.0, -math.pi / 2], [4.5, 5.0, 0.0]])
    np.testing.assert_allclose(score_cones(poses, points, density, math.radians(30), 4.0),
                               [1.0, 0.0, 0.0])  # fmt: skip


def test_sampled_poses_are_navigable_in_range_and_face_a_plane_voxel():
    grid = _open_grid()
    grid.logodds[80:100, 80:100] = grid.model.clamp_max  # a desk in the 2D map
    grid._touch()
    points = _patch(4.0, 4.0, 5.0, 5.0)
    poses = sample_poses(grid, points, 20, 0.25, 2.0, np.random.default_rng(0))
    assert poses.shape == (20, 3)
    cells = grid.to_cell(poses[:, :2])
    assert grid.traversable(0.25)[cells[:, 0], cells[:, 1]].all()
    d = np.hypot(*(points[None, :, :2] - poses[:, None, :2]).transpose(2, 0, 1))
    assert (d.min(axis=1) <= 2.0).all()
    facing = in_view_cones(poses, points, 1e-6 + 0.05, 2.0)  # a plane voxel dead ahead
    assert facing.any(axis=1).all()
    assert len({tuple(c) for c in cells.tolist()}) == 20


def test_qsr_picks_the_pose_facing_the_densest_region():
    grid = _open_grid()
    dense, plain = _patch(1.0, 8.0, 2.0, 9.0), _patch(7.0, 1.0, 9.0, 3.0)  # plain is 4x larger
    points = np.vstack([dense, plain])
    density = np.r_[np.ones(len(dense)), np.full(len(plain), 1e-3)]
    density /= density.sum()
    qsr = select_view(grid, points, density, BODY, ViewMethod.QSR, rng=5)
    planes = select_view(grid, points, None, BODY, "supporting-planes", rng=5)
    assert qsr.selected and planes.selected
    assert [p.x for p in qsr.poses] == [p.x for p in planes.poses]  # the same n samples
    assert qsr.best.score == max(p.score for p in qsr.poses)
    best = np.array([[qsr.best.x, qsr.best.y, qsr.best.yaw]])
    assert in_view_cones(best, dense, BODY.hfov / 2, BODY.detect_range).mean() > 0.5
    # uniform density prefers the larger table; the QSR choice sees mostly the dense one
    chosen = np.array([[planes.best.x, planes.best.y, planes.best.yaw]])
    assert in_view_cones(chosen, plain, BODY.hfov / 2, 4.0).sum() > in_view_cones(
        chosen, dense, BODY.hfov / 2, 4.0).sum()  # fmt: skip
    assert qsr.frustums[0].score >= qsr.frustums[-1].score
    assert qsr.frustums[0].score > 0.3


def test_random_is_one_of_the_samples_and_seeded():
    grid = _open_grid()
    points = np.vstack([_patch(1.0, 8.0, 2.0, 9.0), _patch(7.0, 1.0, 9.0, 3.0)])
    picks = [select_view(grid, points, None, BODY, "random", rng=s) for s in range(6)]
    for sel in picks:
        assert sel.best in sel.poses and len(sel.poses) == 20
    again = select_view(grid, points, None, BODY, "random", rng=3)
    assert again.best == picks[3].best
    assert len({(p.best.x, p.best.y) for p in picks}) > 1


def test_frustums_are_nine_within_limits_and_ranked():
    points = _patch(3.0, 4.0, 4.0, 5.0)
    density = np.where(points[:, 1] > 4.5, 1.0, 0.0)
    density /= density.sum()
    frustums = rank_frustums(np.array([3.5, 2.0, math.pi / 2]), points, density, BODY, 4.0)
    assert len(frustums) == 9
    assert len({(f.pan, f.tilt) for f in frustums}) == 9
    scores = [f.score for f in frustums]
    assert scores == sorted(scores, reverse=True) and scores[0] > 0.9
    for f in frustums:
        assert BODY.pan.contains(f.pan) and BODY.tilt.contains(f.tilt)
    assert frustums[0].pan == 0.0 and frustums[0].tilt < 0.0  # straight ahead, looking down


def test_statuses_and_input_errors():
    grid = _open_grid()
    points = _patch(4.0, 4.0, 5.0, 5.0)
    assert select_view(grid, np.zeros((0, 3)), None, BODY, "random").status is \
        SelectionStatus.NO_SUPPORT  # fmt: skip
    blocked = _open_grid()
    blocked.logodds[...] = blocked.model.clamp_max
    blocked._touch()
    assert select_view(blocked, points, None, BODY, "random").status is SelectionStatus.NO_POSES
    with pytest.raises(ViewSelectionError, match="needs a density"):
        select_view(grid, points, None, BODY, "qsr")
    with pytest.raises(AvsError, match="3 values for 400"):
        select_view(grid, points, np.ones(3), BODY, "qsr")
    with pytest.raises(ValueError):
        select_view(grid, points, None, BODY, "nearest")


def test_desk_scene_qsr_view_sees_a_cup_region():
    knowledge = load_qsr()
    planes = extract_supporting_planes(qsr_scene.voxel_map())
    mixture = build_mixture(knowledge, "cup", qsr_scene.landmarks(knowledge)).mixture
    density = planes.density(mixture)
    grid = qsr_scene.occupancy_grid()
    for seed in range(3):
        qsr = select_view(grid, planes.points, density, BODY, "qsr", rng=seed)
        other = select_view(grid, planes.points, None, BODY, "supporting-planes", rng=seed)
        assert qsr.best.score >= max(p.score for p in qsr.poses)
        # by QSR density, the supporting-planes choice is never better than the QSR one
        k = [p.x for p in other.poses].index(other.best.x)
        assert qsr.poses[k].score <= qsr.best.score
        assert qsr.best.score > 0.2


def test_poses_reachable_from_the_robot_only():
    grid = qsr_scene.occupancy_grid()
    grid.logodds[70:90, 28:32] = grid.model.clamp_max  # close the door at y = 1.5
    grid._touch()
    planes = extract_supporting_planes(qsr_scene.voxel_map())
    rng = np.random.default_rng(0)
    anywhere = sample_poses(grid, planes.points, 200, 0.25, 4.0, rng)
    assert (anywhere[:, 1] < 1.5).any()  # some in the corridor, behind the wall
    lab = sample_poses(grid, planes.points, 200, 0.25, 4.0, rng, start=(2.0, 3.0))
    assert (lab[:, 1] > 1.5).all()
    corridor = select_view(grid, planes.points, None, BODY, "random", rng=1,
                           options=ViewOptions(start=(1.0, 0.75)))  # fmt: skip
    assert corridor.selected and all(p.y < 1.5 for p in corridor.poses)
    # a start inside the inflation zone (brushing a desk) still finds its room
    near_desk = sample_poses(grid, planes.points, 50, 0.25, 4.0, rng, start=(1.5, 5.05))
    assert len(near_desk) == 50 and (near_desk[:, 1] > 1.5).all()


def test_pan_sweep_widens_the_cone_within_the_head_limits():
    assert cone_half_angle(BODY) == pytest.approx(math.radians(30))
    assert cone_half_angle(BODY, math.radians(15)) == pytest.approx(math.radians(45))
    fixed = RobotBody(**{**BODY.__dict__, "pan": JointRange(-0.1, 0.1)})
    assert cone_half_angle(fixed, 1.0) == pytest.approx(math.radians(30) + 0.1)
    grid = _open_grid()
    points = _patch(4.0, 4.0, 5.0, 5.0)
    wide = select_view(grid, points, None, BODY, "supporting-planes", rng=2,
                       options=ViewOptions(pan_sweep=math.radians(30)))  # fmt: skip
    narrow = select_view(grid, points, None, BODY, "supporting-planes", rng=2)
    assert [p.x for p in wide.poses] == [p.x for p in narrow.poses]
    assert all(w.score >= n.score for w, n in zip(wide.poses, narrow.poses, strict=True))
    assert sum(w.score for w in wide.poses) > sum(n.score for n in narrow.poses)


def test_pose_times_by_hand_and_around_a_wall():
    grid = _open_grid()
    start = (2.0, 2.0, 0.0)
    poses = (ScoredPose(4.0, 2.0, 0.0, 0.1), ScoredPose(2.0, 4.0, math.pi / 2, 0.1),
             ScoredPose(2.0, 2.0, math.pi, 0.1))  # fmt: skip
    times = pose_times(poses, grid, start, BODY)
    # 2 m straight ahead at 0.5 m/s; 2 m after a quarter turn; a half turn on the spot
    assert times[0] == pytest.approx(4.0, abs=0.1)
    assert times[1] == pytest.approx(4.0 + math.pi / 2, abs=0.1)
    assert times[2] == pytest.approx(math.pi)
    # a wall from y = 0 to 8 at x = 5: the way to the far side goes round its end
    walled = _open_grid()
    walled.logodds[int(4.95 / 0.05):int(5.05 / 0.05) + 1, : int(8.0 / 0.05)] = \
        walled.model.clamp_max
    walled._touch()
    far = (ScoredPose(7.0, 2.0, 0.0, 0.1),)
    assert pose_times(far, walled, start, BODY)[0] > pose_times(far, grid, start, BODY)[0] + 10


def test_best_rate_trades_density_against_time():
    grid = _open_grid()
    start = (2.0, 2.0, 0.0)
    near = ScoredPose(3.0, 2.0, 0.0, 0.3)  # 2 s away
    far = ScoredPose(8.0, 2.0, 0.0, 0.4)  # 12 s away: more density, less per second
    assert best_rate((far, near), grid, start, BODY, 1.0) is near
    assert best_rate((far, near), grid, start, BODY, 100.0) is far  # long looks: density wins
    boxed = _open_grid()
    boxed.logodds[int(6.0 / 0.05):int(6.1 / 0.05) + 1, :] = boxed.model.clamp_max
    boxed._touch()
    assert best_rate((far,), boxed, start, BODY, 1.0) is None  # behind a wall: no path
    with pytest.raises(ViewSelectionError):
        best_rate((near,), grid, start, BODY, 0.0)


def test_score_poses_scores_any_pose_as_the_selection_does():
    """The robot's own pose is scored like the samples (relook compares it with them)."""
    grid = _open_grid()
    dense, plain = _patch(1.0, 8.0, 2.0, 9.0), _patch(7.0, 1.0, 9.0, 3.0)
    points = np.vstack([dense, plain])
    density = np.r_[np.ones(len(dense)), np.full(len(plain), 1e-3)]
    density /= density.sum()
    view = select_view(grid, points, density, BODY, ViewMethod.QSR, rng=5)
    poses = np.array([[p.x, p.y, p.yaw] for p in view.poses])
    np.testing.assert_allclose(score_poses(poses, points, density, BODY),
                               [p.score for p in view.poses])
    # facing the dense patch from 1.5 m: nearly all of it; facing away: nothing
    toward, away = score_poses(np.array([[1.5, 6.5, math.pi / 2], [1.5, 6.5, -math.pi / 2]]),
                               points, density, BODY)
    assert toward > 0.9 and away == 0.0
    start = (1.5, 6.5, math.pi / 2)
    rates = pose_rates(view.poses, grid, start, BODY, 1.2)
    best = best_rate(view.poses, grid, start, BODY, 1.2)
    assert best is view.poses[int(np.argmax(rates))]
    assert toward / 1.2 > rates.max()  # staying here beats every sample per second
    with pytest.raises(ViewSelectionError, match="density has 3 values"):
        score_poses(poses, points, np.ones(3), BODY)
