"""Exception root of `sim`."""


class SimError(Exception):
    """Root of every error the simulation package raises on purpose."""


class WorldFileError(SimError):
    """A world file is malformed or describes an impossible world (names the offending entry)."""


class MotionError(SimError):
    """A motion request cannot be executed: blocked path, joint limit, malformed target.

    The robot does not move and its clock does not advance when this is raised.
    """


class PathBlockedError(MotionError):
    """`move_along` refused a path because the robot's footprint would hit the world.

    `at` is where the base's centre would have been at first contact, `heading` the direction
    it was driving and `touch` the point of the base's rim that touched (what a bumper or a
    stalled base controller tells a real robot: where, never what).
    """

    def __init__(self, message: str, at: tuple[float, float] | None = None,
                 heading: float | None = None, touch: tuple[float, float] | None = None):
        super().__init__(message)
        self.at = at
        self.heading = heading
        self.touch = touch


class JointLimitError(MotionError):
    """A torso or head target lies outside the robot's joint limits."""


class GenerationError(SimError):
    """A floor plan cannot be generated: bad arguments or a broken placement table."""
