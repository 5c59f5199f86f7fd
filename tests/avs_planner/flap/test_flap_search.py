"""The continual cycle: with the target absent, the omega test ends the search."""

import pytest

from avs_planner.flap.planner import PlannerOptions
from avs_planner.flap.sampling import ViewPose
from avs_planner.flap.search import FlapOptions, FlapSearch, SearchStatus
from bench.flap_scene import PR2_BODY, Scene


@pytest.mark.parametrize("greedy", [False, True], ids=["planner", "greedy"])
def test_omega_stops_a_search_whose_target_is_absent(fresh_scene: Scene, greedy: bool) -> None:
    body, scene = PR2_BODY, fresh_scene
    options = FlapOptions(views=60, clusters=20, greedy=greedy,
                          planner=PlannerOptions(psi=2, phi=2.0, omega=0.05))  # fmt: skip
    search = FlapSearch(body, scene.volumes, options)
    pose = ViewPose(*scene.start, 0.0, 0.0, 0.0)
    history = []
    for _ in range(25):
        decision = search.decide(scene.voxels, scene.grid, pose)
        history.append(decision.p_remaining)
        if decision.status is not SearchStatus.GO:
            break
        assert decision.p_remaining >= 0.05 and decision.plan.next_view is not None
        pose = decision.view.pose
        origin, yaw, pitch = pose.camera(body)  # sense: nothing is there to detect
        scene.voxels.integrate_depth(scene.world.depth(origin, yaw, pitch, size=(64, 48),
                                                       fov=(body.hfov, body.vfov),
                                                       max_range=body.depth_range))  # fmt: skip
    assert decision.status is SearchStatus.DONE
    assert history[-1] < 0.05 < history[0]
    assert len(history) >= 3  # it took several views, not one


def test_a_region_the_map_already_knows_has_no_views(fresh_scene: Scene) -> None:
    from avs_planner.flap.target import TargetBelief, TargetVolume

    scene = fresh_scene
    x, y, _ = scene.start
    seen = TargetVolume((x + 0.3, y - 0.2, 1.25), (x + 0.6, y + 0.2, 1.35), 0.2)  # in the air
    assert not TargetBelief(scene.voxels, [seen]).unknown.any()
    search = FlapSearch(PR2_BODY, [seen], FlapOptions(views=10))
    decision = search.decide(scene.voxels, scene.grid, ViewPose(*scene.start, 0, 0, 0))
    assert decision.status is SearchStatus.NO_VIEWS and decision.view is None


def test_sensed_drops_unrevealed_cells_and_unreachable_views_are_not_planned_again(
        fresh_scene: Scene) -> None:
    scene = fresh_scene
    search = FlapSearch(PR2_BODY, scene.volumes, FlapOptions(views=40, clusters=10))
    decision = search.decide(scene.voxels, scene.grid, ViewPose(*scene.start, 0.0, 0.0, 0.0))
    view = decision.view
    # nothing sensed: every cell the view expected is still unknown, so all are dropped
    assert search.sensed(scene.voxels, view) == view.cells.size > 0
    assert search.exhausted[view.cells].all()
    again = search.decide(scene.voxels, scene.grid, ViewPose(*scene.start, 0.0, 0.0, 0.0))
    assert again.p_remaining < decision.p_remaining
    search.unreachable(again.view)
    third = search.decide(scene.voxels, scene.grid, ViewPose(*scene.start, 0.0, 0.0, 0.0))
    if third.view is not None:
        assert (abs(third.view.pose.x - again.view.pose.x) > 1e-9
                or abs(third.view.pose.y - again.view.pose.y) > 1e-9)
        assert all(((p.pose.x - again.view.pose.x) ** 2 + (p.pose.y - again.view.pose.y) ** 2)
                   >= 0.3 ** 2 for p in search.planned)
