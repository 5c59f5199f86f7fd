"""FLAP views in the switching planner (`views: flap`): cones from FLAP's plan, one-target
probabilities, the option checked; the 2D cones stay the default."""

import copy
from types import SimpleNamespace

import numpy as np
import pytest

from avs_planner.episode.mind import KnownObject
from avs_planner.flap.target import TargetBelief, TargetVolume
from avs_planner.strategies import StrategyError, get_strategy
from avs_planner.strategies.flap_views import FlapViews
from bench.flap_scene import PR2_BODY, build_scene


@pytest.fixture(scope="module")
def scene():
    return build_scene()


def _maker(scene, emitted):
    robot = SimpleNamespace(pose=scene.start, camera_height=PR2_BODY.camera_height,
                            depth=lambda size: pytest.fail("the map exists: no frame needed"))
    return FlapViews(robot, PR2_BODY, lambda kind, **fields: emitted.append((kind, fields)),
                     below=-0.15, views=60, clusters=20, time_limit=None)


def test_flap_cones_carry_the_plan_and_one_target_probabilities(scene):
    """Table 0 of the bench room (top 0.75 m, reset to unknown): a support detected at its
    centre, P(ObjectAt) 0.4. Each cone's probability is 0.4 times the share of the box's
    unknown cells it adds to the cones before it, so they sum to 0.4 * coverage."""
    mind = SimpleNamespace(voxels=copy.deepcopy(scene.voxels), grid=scene.grid)
    lo, hi = scene.volumes[0].lo, scene.volumes[0].hi
    centre = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.375)
    support = KnownObject("object1", "table", centre, "room1")
    emitted = []
    made = _maker(scene, emitted)(mind, support, 0.4, None, "k")
    kind, note = emitted[-1]
    assert kind == "flap" and note["event"] == "cones" and note["flap"], note
    assert 1 <= len(made.cones) <= 6 and 0.0 < made.coverage <= 1.0
    probs = np.array([c.probability for c in made.cones])
    assert np.all(probs >= 0) and probs[0] > 0
    assert probs.sum() == pytest.approx(0.4 * made.coverage)
    assert made.probability == pytest.approx(0.4 * made.coverage)
    for cone in made.cones:
        assert PR2_BODY.torso.contains(cone.torso)
        assert PR2_BODY.pan.contains(cone.head[0]) and PR2_BODY.tilt.contains(cone.head[1])
        cone.check("test")
    # the cones' shares are the plan's new cells among the box's unknown ones
    box = TargetBelief(mind.voxels, [TargetVolume((centre[0] - 0.7, centre[1] - 0.7, 0.6),
                                                  (centre[0] + 0.7, centre[1] + 0.7, 1.05))])
    assert made.coverage * int(box.unknown.sum()) >= 1.0


def test_a_box_the_map_knows_falls_back_to_the_2d_cones(scene):
    """Nothing unknown left in the support's box: FLAP has nothing to plan for."""
    mind = SimpleNamespace(voxels=copy.deepcopy(scene.voxels), grid=scene.grid,
                           config=SimpleNamespace(robot_radius=0.36))
    x, y, _ = scene.start
    support = KnownObject("object9", "table", (x + 0.5, y, 0.6), "room1")  # top 1.2, in air
    lo, hi = (x - 0.2, y - 0.7, 1.05), (x + 1.2, y + 0.7, 1.5)
    mind.voxels.integrate_depth(scene.world.depth((x, y, 1.3), 0.0, -0.2, size=(96, 72),
                                                  max_range=4.5))
    assert not TargetBelief(mind.voxels, [TargetVolume(lo, hi)]).unknown.any()  # (the setup)
    emitted = []
    camera = SimpleNamespace(height=1.3)
    made = _maker(scene, emitted)(mind, support, 0.4, camera, "k")
    assert emitted[-1][1]["flap"] is False and "no unknown cell" in emitted[-1][1]["note"]
    assert made.coverage == 0.9 or not made.cones  # support_cones' set


def test_the_views_option_is_checked():
    switching = get_strategy("switching")
    assert switching.check_options({})["views"] == "cones"  # the 2D cones stay the default
    assert switching.check_options({"views": "flap"})["views"] == "flap"
    with pytest.raises(StrategyError, match=r"option 'views' must be one of cones, flap"):
        switching.check_options({"views": "3d"})
