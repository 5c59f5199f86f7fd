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
