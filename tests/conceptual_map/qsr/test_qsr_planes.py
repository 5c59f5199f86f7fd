"""Supporting planes from a voxel map of the desk scene, and densities over their voxels."""

import numpy as np
import pytest

from bench import qsr_scene
from conceptual_map.metric import VoxelMap
from conceptual_map.qsr import build_mixture, extract_supporting_planes, load_qsr

RES = 0.05


@pytest.fixture(scope="module")
def planes():
    return extract_supporting_planes(qsr_scene.voxel_map(RES))


def _desk_segments(planes):
    return [s for s in planes.segments if abs(s.height - 0.74) <= RES]


def test_desk_tops_are_found_where_the_desks_are(planes):
    desks = _desk_segments(planes)
    assert len(desks) == 4
    tops = list(qsr_scene.desk_tops().values())
    for segment in desks:
        match = [t for t in tops if np.allclose(segment.bounds, t[:4], atol=RES / 2)]
        assert len(match) == 1, segment.bounds
        assert segment.height == pytest.approx(0.74, abs=RES)
        # the desk top minus the monitor's foot (and a cup's), plus the keyboard's top
        full = (match[0][2] - match[0][0]) * (match[0][3] - match[0][1])
        assert 0.85 * full < segment.area < full + 1e-9
    assert len(planes) == sum(len(s.cells) for s in planes.segments) == planes.points.shape[0]
    assert np.array_equal(np.unique(planes.segment_of), np.arange(len(planes.segments)))


def test_no_plane_under_the_monitors_and_heights_filter_their_tops(planes):
    monitors = [s for s in planes.segments if abs(s.height - 1.14) <= RES]
    assert len(monitors) == 4  # 0.5 x 0.15 m tops at 1.14 m are inside 0.4-1.2 m
    low = extract_supporting_planes(qsr_scene.voxel_map(RES), z_range=(0.4, 1.0))
    assert len(low.segments) == 4 and all(abs(s.height - 0.74) <= RES for s in low.segments)
    poses = qsr_scene.object_poses()
    for name in ("monitor1", "monitor4"):
        x, y = poses[name][1:3]
        near = np.hypot(*(low.points[:, :2] - [x, y]).T) < 0.05
        assert not near.any()  # occupied above: not a supporting surface


def test_floor_overhang_and_small_surfaces_are_not_planes():
    voxels = VoxelMap((0.0, 0.0, 0.0), (2.0, 2.0, 2.0), RES)
    qsr_scene.fill_voxels(voxels, [(0.2, 0.2, 0.0, 0.8, 0.8, 0.7),  # a table
                                   (0.2, 0.2, 0.75, 0.8, 0.8, 0.8),  # a board 5 cm above it
                                   (1.2, 1.2, 0.0, 1.3, 1.3, 0.7)])  # a post: 0.01 m^2 top
    planes = extract_supporting_planes(voxels)
    assert [round(s.height, 2) for s in planes.segments] == [0.8]  # only the board's top
    assert extract_supporting_planes(voxels, clearance=0.0, min_area=0.0).segments


def test_unknown_space_above_is_not_free():
    voxels = VoxelMap((0.0, 0.0, 0.0), (1.0, 1.0, 1.5), RES)
    qsr_scene.fill_voxels(voxels, [(0.2, 0.2, 0.0, 0.8, 0.8, 0.7)])
    voxels.logodds[:, :, 14:] = 0  # never observed above the table
    assert len(extract_supporting_planes(voxels)) == 0


def test_density_projects_the_mixture_onto_plane_voxels(planes):
    knowledge = load_qsr()
    mixture = build_mixture(knowledge, "cup", qsr_scene.landmarks(knowledge)).mixture
    density = planes.density(mixture)
    assert density.sum() == pytest.approx(1.0) and (density >= 0).all()
    uniform = planes.uniform_density()
    assert uniform.sum() == pytest.approx(1.0) and np.ptp(uniform) == 0
    poses = qsr_scene.object_poses()
    cup = np.hypot(*(planes.points[:, :2] - poses["cup1"][1:3]).T) < 0.1
    far = np.hypot(*(planes.points[:, :2] - poses["monitor1"][1:3]).T) < 0.3
    assert density[cup].mean() > 5 * density[far].mean()
