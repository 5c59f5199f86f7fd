"""The fence between the robot's mind and the world, in code: strategies and the executor
are handed the robot's sensors and motions, and nothing through which the simulator's truth
(object poses, room categories, which detection was which object) could be read."""

from __future__ import annotations

import pytest

from avs_planner.episode.robot_api import METHODS, PROPERTIES, Robot, RobotFence
from avs_planner.harness import EpisodeSpec
from avs_planner.harness.runner import Episode


@pytest.fixture(scope="module")
def episode():
    episode = Episode(EpisodeSpec.from_dict({"target": "cerealbox", "world": "office",
                                             "seed": 1, "time_budget_s": 5.0}))
    yield episode
    episode.robot.world.close()


def test_the_mind_side_gets_the_robot_through_the_fence(episode) -> None:
    for robot in (episode.executor.robot, episode.context.robot):
        assert type(robot) is RobotFence and isinstance(robot, Robot)
        for truth in ("world", "robot", "truth_of", "model", "__dict__"):
            with pytest.raises(AttributeError):
                getattr(robot, truth)
        with pytest.raises(AttributeError):
            robot.detect = lambda labels: []  # members cannot be swapped either
    assert hasattr(episode.robot, "world")  # the harness keeps the adapter itself


def test_the_fence_forwards_the_robot_protocol(episode) -> None:
    sensed, adapter = episode.context.robot, episode.robot
    for name in PROPERTIES:
        assert getattr(sensed, name) == getattr(adapter, name)
    assert sensed.body() == adapter.body()
    before = sensed.clock
    frame = sensed.detect(["cerealbox", "table"])
    assert sensed.clock > before  # a frame costs sensing time on the robot's own clock
    assert all(s.label in ("cerealbox", "table") for s in frame)
    assert set(METHODS) | set(PROPERTIES) == {
        n for n in dir(Robot) if not n.startswith("_")}
