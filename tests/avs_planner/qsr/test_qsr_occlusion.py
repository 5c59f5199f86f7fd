"""Occlusion in view selection: lines of sight through the voxel map (walls and monitors hide
plane voxels; a table top's own voxels do not)."""

import numpy as np

from avs_planner.qsr import ViewOptions, line_of_sight, select_view
from bench import qsr_scene
from conceptual_map.qsr import extract_supporting_planes
from tests.avs_planner.qsr.test_qsr_view_selection import BODY


def test_walls_and_monitors_hide_plane_voxels_but_the_table_top_does_not():
    voxels = qsr_scene.voxel_map()
    planes = extract_supporting_planes(voxels)
    x0, y0, x1, y1, _ = qsr_scene.desk_tops()["desk1"]
    on_desk = (planes.points[:, 0] > x0) & (planes.points[:, 0] < x1) & \
        (planes.points[:, 1] > y0) & (planes.points[:, 1] < y1)
    front = planes.points[on_desk & (planes.points[:, 1] < 5.4)]  # between keyboard and edge
    behind = planes.points[on_desk & (planes.points[:, 1] > 5.8)
                           & (np.abs(planes.points[:, 0] - 1.5) < 0.15)]  # behind monitor1
    assert len(front) and len(behind)
    lab = np.array([[1.5, 3.5, 1.4]])  # in front of desk1, in the lab
    corridor = np.array([[1.5, 0.75, 1.4]])  # behind the lab's wall
    assert line_of_sight(voxels, lab, front).all()
    assert not line_of_sight(voxels, lab, behind).any()
    assert not line_of_sight(voxels, corridor, front).any()
    # only the pairs asked for are tested
    pairs = np.zeros((1, len(front)), dtype=bool)
    pairs[0, 0] = True
    assert line_of_sight(voxels, lab, front, pairs).sum() == 1


def test_occlusion_only_lowers_cone_scores():
    voxels, grid = qsr_scene.voxel_map(), qsr_scene.occupancy_grid()
    planes = extract_supporting_planes(voxels)
    free = select_view(grid, planes.points, None, BODY, "supporting-planes", rng=4)
    hidden = select_view(grid, planes.points, None, BODY, "supporting-planes", rng=4,
                         options=ViewOptions(occlusion=voxels))
    open_scores = np.array([p.score for p in free.poses])
    seen_scores = np.array([p.score for p in hidden.poses])
    assert np.all(seen_scores <= open_scores + 1e-12)
    assert np.any(seen_scores < open_scores)


def test_a_belief_over_the_planes_steers_the_supporting_planes_method():
    """Given a density (uniform less where it looked), the non-QSR methods use it."""
    voxels, grid = qsr_scene.voxel_map(), qsr_scene.occupancy_grid()
    planes = extract_supporting_planes(voxels)
    density = np.where(planes.points[:, 0] > 5.0, 1.0, 0.0)
    density /= density.sum()
    view = select_view(grid, planes.points, density, BODY, "supporting-planes", rng=0)
    assert view.best.score > 0 and view.best.x > 2.5


def _literal_line_of_sight(voxels, origin, point, skip=0.15):  # noqa: ANN001, ANN202
    """One segment sampled every voxel length up to `skip` before its end, in float64."""
    a, b = np.asarray(origin, float), np.asarray(point, float)
    length = float(np.linalg.norm(b - a))
    direction = (b - a) / max(length, 1e-9)
    res, shape = voxels.resolution, np.asarray(voxels.shape)
    for k in range(int(np.floor(max(length - skip, 0.0) / res)) + 1):
        cell = np.floor((a + k * res * direction - np.asarray(voxels.origin)) / res).astype(int)
        if np.all((cell >= 0) & (cell < shape)) and \
                voxels.logodds[tuple(cell)] >= voxels.model.occupied_at:
            return False
    return True


def test_line_of_sight_matches_the_segment_walked_one_voxel_at_a_time():
    """The vectorised test (box cut, length-sorted chunks) agrees with a literal walk, also for
    cameras outside the map and for pairs of very different lengths."""
    voxels = qsr_scene.voxel_map()
    planes = extract_supporting_planes(voxels)
    rng = np.random.default_rng(3)
    cameras = np.column_stack([rng.uniform(-1.0, 9.0, 6), rng.uniform(-1.0, 7.0, 6),
                               rng.uniform(0.9, 1.6, 6)])
    points = planes.points[rng.choice(len(planes), 60, replace=False)]
    fast = line_of_sight(voxels, cameras, points, chunk=97)
    slow = np.array([[_literal_line_of_sight(voxels, c, p) for p in points] for c in cameras])
    assert fast.any() and not fast.all()
    assert np.array_equal(fast, slow)
