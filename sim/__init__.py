"""The simulated world: PyBullet scenes from world files, robot models, timed motion, sensors.

Imports nothing else of ours: it is the world, not the robot's mind. Typical use:

    with load_world("office", seed=1) as world:
        robot = world.robot
        robot.move_along([(7.0, 3.2), (7.0, 5.5)])
        scan, frame = robot.scan(), robot.detect(["cerealbox"])

See `sim/README.md` for the world-file format, the time model and the sensor models.
"""

import sim._quiet_pybullet  # noqa: F401  (first: pybullet without its banner)
from sim.camera import DetectorConfig
from sim.errors import JointLimitError, MotionError, PathBlockedError, SimError, WorldFileError
from sim.place_classifier import PlaceClassifier
from sim.robot import MotionResult, Robot
from sim.robot_models import PIONEER, PR2, ROBOT_MODELS, RobotModel
from sim.scene import World, load_world
from sim.sensor_data import (
    CameraView,
    DepthScan,
    Detection,
    DetectionFrame,
    LaserScan,
    PlaceObservation,
)
from sim.time_model import TimeModel
from sim.world_file import builtin_worlds, load_world_spec
from sim.world_spec import WorldSpec

__all__ = [
    "PIONEER", "PR2", "ROBOT_MODELS", "CameraView", "DepthScan", "Detection", "DetectionFrame",
    "DetectorConfig", "JointLimitError", "LaserScan", "MotionError", "MotionResult",
    "PathBlockedError", "PlaceClassifier", "PlaceObservation", "Robot", "RobotModel", "SimError",
    "TimeModel", "World", "WorldFileError", "WorldSpec", "builtin_worlds", "load_world",
    "load_world_spec",
]
