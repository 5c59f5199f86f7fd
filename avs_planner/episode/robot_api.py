"""What the robot's mind may ask of its robot: the fence between the mind and the world.

`Robot` is the protocol strategies, the executor and the mind program against: the robot's
own pose, clock, odometry and body, its motions, and its sensors (laser scans, depth frames,
detections, the place classifier). Nothing in it names the world.

`fence(robot)` is how the episode hands a robot over: an object with exactly those members
and nothing else, forwarding to the simulator adapter (`harness/sim_robot.py`) through closures.
The adapter holds the world (`world`, the simulated `robot`, `truth_of` for scoring); through
the fence none of it can be reached by attribute, so a planner or strategy that tried to
read an object's true pose or a room's true category fails with an AttributeError instead of
quietly cheating. The import contracts (`pyproject.toml`, `[tool.importlinter]`) keep the
same modules from importing the simulator; the fence keeps them from being handed it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol, runtime_checkable

from avs_planner.body import RobotBody
from avs_planner.episode.outcome import SeenLike


@runtime_checkable
class Robot(Protocol):
    """The robot as its mind knows it: proprioception, motion and sensing, timed."""

    @property
    def pose(self) -> tuple[float, float, float]: ...

    @property
    def clock(self) -> float: ...

    @property
    def odometry(self) -> float: ...

    @property
    def camera_height(self) -> float: ...

    @property
    def last_contact(self) -> tuple[float, float] | None:
        """Where the base's rim touched something on the last blocked move (a bumper)."""

    def body(self) -> RobotBody: ...

    def move_along(self, path: Sequence[tuple[float, float]]) -> bool: ...

    def turn_to(self, yaw: float) -> None: ...

    def set_torso(self, height: float) -> None: ...

    def look(self, pan: float, tilt: float) -> None: ...

    def scan(self) -> Any: ...

    def depth(self, size: tuple[int, int] = (32, 24)) -> Any: ...

    def detect(self, labels: Sequence[str]) -> Sequence[SeenLike]: ...

    def classify_place(self) -> str | None: ...


METHODS = ("body", "move_along", "turn_to", "set_torso", "look", "scan", "depth", "detect",
           "classify_place")
PROPERTIES = ("pose", "clock", "odometry", "camera_height", "last_contact")


class RobotFence:
    """A `Robot` and nothing more (see `fence`)."""

    __slots__ = ("_read",) + METHODS

    _read: Callable[[str], Any]

    def __init__(self, read: Callable[[str], Any], calls: dict[str, Callable[..., Any]]):
        object.__setattr__(self, "_read", read)
        for name in METHODS:
            object.__setattr__(self, name, calls[name])

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"the robot's members cannot be replaced ({name})")

    def __repr__(self) -> str:
        return "RobotFence()"

    @property
    def pose(self) -> tuple[float, float, float]:
        return self._read("pose")

    @property
    def clock(self) -> float:
        return self._read("clock")

    @property
    def odometry(self) -> float:
        return self._read("odometry")

    @property
    def camera_height(self) -> float:
        return self._read("camera_height")

    @property
    def last_contact(self) -> tuple[float, float] | None:
        return self._read("last_contact")


def fence(robot: Robot) -> RobotFence:
    """`robot`'s protocol members, forwarded through closures: the fenced object has no
    attribute that leads back to the adapter or the world behind it."""
    def read(name: str) -> Any:
        if name not in PROPERTIES:
            raise AttributeError(name)
        return getattr(robot, name)

    def forward(name: str) -> Callable[..., Any]:
        def call(*args: Any, **kwargs: Any) -> Any:
            return getattr(robot, name)(*args, **kwargs)
        call.__name__ = call.__qualname__ = name
        return call

    return RobotFence(read, {name: forward(name) for name in METHODS})
