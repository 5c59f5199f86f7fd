"""Fixtures for the episode tests: a mind that has looked around the office corridor once."""

from __future__ import annotations

import pytest

from avs_planner.episode.executor import Executor
from avs_planner.episode.mind import Mind
from avs_planner.episode.state_builder import SearchTask, StateBuilder
from avs_planner.episode.viewcones import CameraModel
from avs_planner.harness.sim_robot import load_spec, open_world


def _look_around_the_corridor():
    robot = open_world(load_spec("office", start=(6.0, 3.2, 0.0)), seed=1)
    mind = Mind()
    builder = StateBuilder(mind, SearchTask("cerealbox"))
    cam = robot.robot.model.camera
    executor = Executor(robot, mind, builder, CameraModel(robot.camera_height, cam.hfov,
                                                          cam.detect_range), lambda *a, **k: None)
    executor.look_around()
    return robot, mind, builder, executor


@pytest.fixture(scope="module")
def corridor_mind():
    """Robot at the office corridor start, one look around; yields (mind, builder, robot)."""
    robot, mind, builder, _ = _look_around_the_corridor()
    yield mind, builder, robot
    robot.world.close()


@pytest.fixture()
def corridor():
    """The same, fresh for each test (tests change the mind); yields (mind, builder,
    executor)."""
    robot, mind, builder, executor = _look_around_the_corridor()
    yield mind, builder, executor
    robot.world.close()


@pytest.fixture()
def switching_loop():
    """Make a `SwitchingLoop` over an executor and state builder made without its settings:
    gives them the settings the loop decides first, as the episode builds them
    (`LoopConfig.executor_config`, `builder_config`)."""
    from avs_planner.strategies.switching.loop import LoopConfig, SwitchingLoop

    def make(builder, executor, trace, config=None, should_stop=None):  # noqa: ANN001, ANN202
        config = config or LoopConfig()
        executor.config = config.executor_config(executor.config)
        executor.watching = executor.config.watch
        if executor.config.glimpses and executor.glimpses is None:
            executor.enable_glimpses()
        if executor.config.landmarks:
            executor.enable_landmarks()
        builder.config = config.builder_config(builder.config)
        return SwitchingLoop(builder, executor, trace, config, should_stop)

    return make
