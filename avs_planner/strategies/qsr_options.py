"""Options of the QSR strategies and their defaults (apart from `qsr.py`, so the registry can
name them without importing the strategies)."""

from __future__ import annotations

from typing import Any

from avs_planner.errors import AvsError

OPTIONS: dict[str, Any] = {
    "abort_s": 120.0,  # the QSR paper's search monitor: simulated seconds of search before abort
    "n_poses": 20,  # poses sampled per selection (Algorithm 1's n)
    "frustums": 2,  # looks a pose is rated for (utility rate's look time), and the looks
    # taken at each pose without relook (the best of the nine ranked frustums)
    "pan_sweep_deg": 0.0,  # widen the 2D cone by a head pan each way (the QSR paper's Table IV: 60)
    "seen_weight": 0.25,  # density factor of a voxel per look that covered it: about the
    # chance that a look misses a cup in view (camera miss 0.2, + 0.8 x 0.2^2 unconfirmed)
    "rerank": True,  # rank the frustums at a pose again after each look that found nothing
    # (on the belief with that look's miss), instead of taking the first ranking's next one
    "relook": True,  # with utility rate (not random): after a look that found nothing,
    # another look from where the robot stands (any frustum, the one just used included, on
    # the updated belief) competes with the sampled poses by the same score per second
    "max_looks": 9,  # looks from one pose at most (a safety bound on relook; each look
    # multiplies what it covered by seen_weight, so the utility moves on long before)
    "confirm_frames": 2,  # frames to confirm a first detection (any one agreeing suffices)
    "uniform_floor": 0.02,  # qsr: share of uniform density mixed in (wrong QSRs stay findable)
    "utility": "rate",  # pose choice: rate (eq. 2's score per second of getting there and
    # looking, Sarmiento et al.'s p/t) or eq2 (the QSR paper's argmax of eq. 2, travel ignored)
    "max_poses": 40,  # view poses before giving up regardless of time
    "survey_stops": 12,  # frontier stops of the survey at most (after looking round at the
    # start); it ends sooner when no frontier is left: the QSR paper starts with complete maps
    "survey_headings": 8,  # directions looked at per survey stop
    "depth_columns": 64,  # depth frame size (columns x rows)
    "depth_rows": 48,
    "watch": False,  # the detector watches for the target while driving to a view pose
    "learn": True,  # after a found object, update the knowledge for the rest of the episode
    # (and the experience store's QSR counts, when the episode has a store)
}

REMOVED = {
    "learn_file": "the QSR counts a search learns are kept in the experience store: give "
                  "one with `avs simulate --experience PATH` (the episode spec's "
                  "`experience`); see docs/learning.md",
}
"""Options the QSR strategies no longer take -> what to use instead."""

UTILITIES = ("rate", "eq2")


def check_options(options: dict[str, Any]) -> None:
    """The registry's check of the QSR strategies' options beyond their types."""
    if options["utility"] not in UTILITIES:
        raise AvsError(f"option 'utility' must be one of {', '.join(UTILITIES)}, "
                       f"got {options['utility']!r}")
    if options["max_looks"] < 1:
        raise AvsError(f"option 'max_looks' must be >= 1, got {options['max_looks']}")
