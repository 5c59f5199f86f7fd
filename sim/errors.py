"""Exception root of `sim`."""


class SimError(Exception):
    """Root of every error the simulation package raises on purpose."""


class WorldFileError(SimError):
    """A world file is malformed or describes an impossible world (names the offending entry)."""
