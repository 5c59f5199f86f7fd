"""Errors of experiment campaigns: bad campaign files, unusable output directories."""

from avs_planner.errors import AvsError


class CampaignError(AvsError):
    """A campaign cannot be read or run; the message names the file and the entry."""
