"""View sampling respects every constraint of §3.1, and ray casting is optimistic but honest."""

import math

import numpy as np
import pytest

from avs_planner.flap.sampling import SamplerOptions, ViewSampler
from avs_planner.flap.target import TargetBelief, TargetVolume
from avs_planner.flap.visibility import OCCUPIED, Cameras, CastGrid, visible_cells
from bench.flap_scene import PIONEER_BODY, PR2_BODY, Scene
from conceptual_map.metric import CellState, VoxelMap
from conceptual_map.metric.raycast import traverse_reference


@pytest.fixture(scope="module", params=[PR2_BODY, PIONEER_BODY], ids=["pr2", "pioneer"])
def sampled(request, scene: Scene, belief: TargetBelief):  # noqa: ANN001, ANN201
    sampler = ViewSampler(scene.voxels, scene.grid, request.param, belief)
    return sampler, sampler.sample(120, seed=3)


def test_it_finds_the_views_it_was_asked_for(sampled) -> None:  # noqa: ANN001
    sampler, views = sampled
    assert len(views) == 120
    assert all(v.cells.size >= 1 for v in views)


def test_joints_stay_within_the_body_limits(sampled) -> None:  # noqa: ANN001
    sampler, views = sampled
    body = sampler.body
    for v in views:
        assert body.torso.contains(v.pose.torso)
        assert body.pan.contains(v.pose.pan)
        assert body.tilt.contains(v.pose.tilt)


def test_camera_points_at_its_target_within_range(sampled) -> None:  # noqa: ANN001
    sampler, views = sampled
    for v in views:
        origin, yaw, pitch = v.pose.camera(sampler.body)
        d = np.asarray(v.target) - np.asarray(origin)
        dist = float(np.linalg.norm(d))
        assert sampler.options.min_range <= dist <= sampler.max_range + 1e-9
        assert math.cos(yaw - math.atan2(d[1], d[0])) == pytest.approx(1.0, abs=1e-9)
        assert pitch == pytest.approx(math.asin(d[2] / dist), abs=1e-9)


def test_base_is_collision_free_with_the_footprint(sampled, scene: Scene) -> None:  # noqa: ANN001
    sampler, views = sampled
    grid, radius = scene.grid, sampler.body.footprint_radius
    clearance, states = grid.clearance(), grid.state_grid()
    for v in views:
        cell = grid.cell_of((v.pose.x, v.pose.y))
        assert states[cell] == CellState.FREE
        assert clearance[cell] >= radius


def test_camera_is_on_the_known_side_of_the_frontier(sampled) -> None:  # noqa: ANN001
    sampler, views = sampled
    index = {tuple(np.round(t, 6)): k for k, t in enumerate(sampler.targets)}
    for v in views:
        k = index[tuple(np.round(v.target, 6))]
        origin, _, _ = v.pose.camera(sampler.body)
        line_of_sight = np.asarray(origin) - np.asarray(v.target)
        assert float(line_of_sight @ sampler.normals[k]) > 0.0  # angle < 90 degrees


def test_views_see_only_unknown_region_cells_in_range_and_fov(sampled, belief) -> None:  # noqa: ANN001
    sampler, views = sampled
    body = sampler.body
    res = sampler.voxels.resolution
    for v in views[:40]:
        assert np.all(belief.unknown[v.cells])
        origin, yaw, pitch = v.pose.camera(body)
        rel = belief.centres[v.cells] - np.asarray(origin)
        assert np.all(np.linalg.norm(rel, axis=1) <= sampler.max_range + res)
        axis = np.array([math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw),
                         math.sin(pitch)])  # fmt: skip
        off_axis = np.arccos(np.clip(rel @ axis / np.linalg.norm(rel, axis=1), -1, 1))
        half_diag = math.hypot(body.hfov, body.vfov) / 2
        slack = res / np.linalg.norm(rel, axis=1)  # a cell's angular size
        assert np.all(off_axis <= half_diag + slack)


def test_reported_cells_are_in_sight_through_unknown_space(sampled, scene: Scene) -> None:  # noqa: ANN001
    """Almost every cell a view reports has a clear line from the camera to its centre
    (the straight-line check is stricter than a ray that clips the cell's corner)."""
    sampler, views = sampled
    voxels, belief = scene.voxels, sampler.belief
    occupied = voxels.states() == CellState.OCCUPIED
    clear = total = 0
    for v in views[:10]:
        origin, _, _ = v.pose.camera(sampler.body)
        start = (np.asarray(origin) - voxels.origin) / voxels.resolution
        for cell in v.cells[:: max(1, v.cells.size // 40)]:
            end = (belief.centres[cell] - voxels.origin) / voxels.resolution
            path = traverse_reference(start, end)[:-1]
            total += 1
            clear += not any(occupied[c] for c in path if all(0 <= c[i] < voxels.shape[i]
                                                               for i in range(3)))
    assert clear / total >= 0.9


def _corridor(wall_at: float | None) -> list[np.ndarray]:
    """A camera looking along +x into a 5 x 2 x 2 block of unknown region cells; optionally
    an occupied slab across the corridor at x = wall_at."""
    voxels = VoxelMap(origin=(0.0, 0.0, 0.0), size=(2.0, 1.0, 1.0), resolution=0.1)
    belief = TargetBelief(voxels, [TargetVolume((1.0, 0.4, 0.4), (1.5, 0.6, 0.6), 0.2)])
    codes = belief.unknown_lookup(voxels)
    if wall_at is not None:
        cells = voxels.cells_in_box((wall_at, 0.0, 0.0), (wall_at + 0.05, 1.0, 1.0))
        codes[np.ravel_multi_index(tuple(cells.T), voxels.shape)] = OCCUPIED
    grid = CastGrid(codes, voxels.shape, voxels.origin, voxels.resolution,
                    np.array([[1.0, 0.4, 0.4]]), np.array([[1.5, 0.6, 0.6]]))
    cams = Cameras(np.array([[0.21, 0.5, 0.5]]), np.array([0.0]), np.array([0.0]))
    return visible_cells(grid, cams, (1.0, 1.0), 3.0, rays=(12, 12), step=0.5)


def test_optimistic_rays_pass_unknown_but_stop_at_occupied_cells() -> None:
    assert _corridor(None)[0].size == 5 * 2 * 2  # all of it: unknown space is see-through
    assert _corridor(0.61)[0].size == 0  # a wall in front hides it all
    behind = _corridor(1.21)[0]  # a slab in the middle of the block (third layer)
    assert behind.size == 2 * 2 * 2  # the two layers in front of it


def test_anytime_budget_and_seed(scene: Scene, belief) -> None:  # noqa: ANN001
    sampler = ViewSampler(scene.voxels, scene.grid, PR2_BODY, belief,
                          SamplerOptions(batch=16))  # fmt: skip
    assert len(sampler.sample(1000, timeout=0.0)) <= 16
    a, b = sampler.sample(10, seed=7), sampler.sample(10, seed=7)
    assert [x.pose for x in a] == [y.pose for y in b]
