"""A mapped room with tables and a shelf, shared by the FLAP tests (built once)."""

from __future__ import annotations

import copy

import pytest

from avs_planner.flap.target import TargetBelief
from bench.flap_scene import Scene, build_scene


@pytest.fixture(scope="session")
def scene() -> Scene:
    return build_scene()


@pytest.fixture()
def fresh_scene(scene: Scene) -> Scene:
    """A copy the test may change (its maps are integrated into)."""
    return copy.deepcopy(scene)


@pytest.fixture(scope="session")
def belief(scene: Scene) -> TargetBelief:
    return TargetBelief(scene.voxels, scene.volumes)
