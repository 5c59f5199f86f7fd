"""What moves and searches cost in an AVS problem, in the robot's own seconds.

Every cost is seconds of robot time, so that the reward R (the seconds a found object is
worth) weighs them rightly: a move costs its path length over the body's speed, and a search
the mean of a prior from the body (the view cones it is given, each a drive, a quarter turn
and a look) and the searches of that kind timed in this episode. Without a body, or with
`BuilderConfig.seconds` off, the active visual search paper's own numbers in its own units.

Kept apart from the state builder (`state_builder.py`), which assembles a problem's objects
and atoms and only writes these prices into it: pricing has its own inputs (the body, the
episode's timings) and another user, the building-level stopping rule, which prices the next
step the same way (`strategies/switching/stopping.py`, through `StateBuilder.search_cost`
and `StateBuilder.travel_speed`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from avs_planner.body import RobotBody

if TYPE_CHECKING:
    from avs_planner.episode.state_builder import BuilderConfig

RELATIONS = ("in", "on")  # a search's relation; `BuilderConfig`'s pairs are in this order

# (a search of the target?, its relation) -> the seconds such searches took in this episode
SearchTimes = dict[tuple[bool, str], list[float]]


def travel_speed(body: RobotBody | None, config: BuilderConfig) -> float:
    """Metres per unit of move cost (the body's speed when costs are seconds, else 1)."""
    return body.linear_speed if config.seconds and body is not None else 1.0


def move_cost(length: float, body: RobotBody | None, config: BuilderConfig) -> float:
    """A MOVE along `length` metres of the place graph."""
    return round(length / travel_speed(body, config), 3)


def search_prior(body: RobotBody | None, config: BuilderConfig, target: bool,
                 relation: str) -> float:
    """A search's cost before any was timed: its view cones (`cones_per_search`, each a drive
    of `cone_spacing`, a quarter turn and two frames) when costs are seconds, else the
    active visual search paper's number for a search of the target or of a support."""
    k = RELATIONS.index(relation)
    prior = (config.target_search_cost if target else config.support_search_cost)[k]
    if config.seconds and body is not None:
        per_cone = (config.cone_spacing[k] / body.linear_speed + body.turn_time(math.pi / 2)
                    + 2.0 * body.sensing_time)
        prior = config.cones_per_search[k] * per_cone
    return prior


def search_cost(body: RobotBody | None, config: BuilderConfig, times: SearchTimes,
                target: bool, relation: str) -> float:
    """The prior cost of a search of this kind, averaged with the ones timed so far (the
    prior counts as one of them)."""
    prior = search_prior(body, config, target, relation)
    timed = times.get((target, relation), []) if config.seconds else []
    return round((prior + sum(timed)) / (1 + len(timed)), 3)
