"""Errors of the episode runner: bad specs and scenarios, named where they are wrong."""

from avs_planner.errors import AvsError


class EpisodeError(AvsError):
    """An episode cannot start or continue: bad spec, unknown label, broken scenario file."""
