"""Knowing when to stop: a building-level belief that the target is still to be found.

The switching planner's plans each carry one chain of assumptions, so "no plan above the
threshold" says little about the building as a whole, and a plan that explores is never
judged worth its cost (`SwitchingLoop._worth_it`): a robot looking for something that is not
there explored every frontier and ran out of time. Here the conceptual map answers for the
whole building: P(target in space not yet searched | everything seen), from its
existence model over known rooms (their floors, supports not found yet, the spaces of known
supports, all thinned by every look, glimpses included) and over what placeholders may lead
to (the exploration hypotheses of Göbelbecker et al., "A Planning Approach to Active Visual
Search in Large Environments").

The stopping rule uses the paper's own objective c + R(1 - p): any continuation finds the
target with at most the probability left, P, and costs at least the cheapest first step (the
way to the nearest room or placeholder left plus the cheapest way to find the target there:
a search, or one look around, since the detector watches wherever the robot arrives).
When R * P is not more than that, going on is worse than giving up by the planner's
measure, whatever plan it would make; the give-up names the probability left.
The test is on the whole of P, not option by option: exploring reveals several rooms at once,
and ten placeholders of p = 0.09 each are worth going on for although none alone is (a
first version judged each alone and gave up 9 s into an apartment with P = 0.59 left).
Costs are in the planner's units (`StateBuilder`: metres over the body's speed, search
costs; a look in the body's seconds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from avs_planner.episode.mind import Mind
from avs_planner.episode.state_builder import StateBuilder
from conceptual_map.metric.path_planning import PathQueryError, distance_field


@dataclass(frozen=True)
class Option:
    """One way to go on: search a known room or explore behind a placeholder."""

    kind: str  # "room" or "placeholder"
    name: str
    p: float  # P(the target is in the space it opens)
    cost: float  # a lower bound on what it costs (planner units)

    def value(self, reward: float) -> float:
        return reward * self.p - self.cost


@dataclass(frozen=True)
class Remaining:
    """The building-level belief: P(target in space not yet searched) and the options."""

    p: float
    options: tuple[Option, ...]

    def best(self, reward: float) -> Option | None:
        """The option worth most on its own (for traces)."""
        return max(self.options, key=lambda o: o.value(reward), default=None)

    def cheapest(self) -> Option | None:
        return min(self.options, key=lambda o: o.cost, default=None)

    def worth_going_on(self, reward: float) -> bool:
        """Some continuation may be worth more than giving up: R * P exceeds the cost of
        the cheapest first step (an upper bound on any continuation's value)."""
        cheapest = self.cheapest()
        return cheapest is not None and reward * self.p > cheapest.cost

    def describe(self, reward: float) -> str:
        cheapest = self.cheapest()
        head = f"P(target in space not yet searched) = {self.p:.3g}"
        if cheapest is None:
            return f"{head}; nothing is left to search or explore"
        return (f"{head}; no continuation is worth its cost: reward {reward:g} x P is less "
                f"than the cheapest next step ({cheapest.kind} {cheapest.name}, cost >= "
                f"{cheapest.cost:.0f})")


def remaining(mind: Mind, builder: StateBuilder, here: tuple[float, float],
              look: float = 0.0) -> Remaining:
    """The building-level belief for the builder's target, seen from the robot at `here`.
    `look`: what one look around costs (the detector watches as the robot arrives anywhere,
    so a look is the cheapest way to find the target in a room, cheaper than any search)."""
    label, cmap, pm = builder.task.target, mind.cmap, mind.place_map
    try:
        field_ = distance_field(mind.grid, here, mind.config.robot_radius)
    except PathQueryError:
        field_ = None
    speed = builder.travel_speed()
    search = _cheapest_searches(builder, look)
    options: list[Option] = []
    for rid, room in pm.rooms.items():
        if not cmap.graph.has_room(rid):
            continue
        spots = [pm.places[p].position for p in room.places if p in pm.places]
        p = cmap.p_unsearched(label, rid)
        supported = bool(cmap.objects.sublocations(rid, label))
        cost = _travel(mind, field_, here, spots) / speed + (search.known if supported
                                                        else search.fresh)
        options.append(Option("room", rid, p, cost))
    tries, limit = mind.tried_placeholders, builder.config.max_placeholder_tries
    for pid, ph in pm.placeholders.items():
        if tries.get(pid, 0) >= limit or pid not in cmap.placeholders:
            continue
        p = cmap.p_beyond_placeholder(label, pid)
        cost = _travel(mind, field_, here, [ph.position]) / speed + search.fresh
        options.append(Option("placeholder", pid, p, cost))
    # the spaces are disjoint: their expected counts add (under an uncertain building rate
    # their probabilities are not independent, so 1 - prod(1 - p) would overstate P)
    mass = sum(float(cmap.mass(label, o.p)) for o in options)
    return Remaining(float(cmap.p_any(label, mass)) if options else 0.0, tuple(options))


@dataclass(frozen=True)
class _Searches:
    known: float  # the cheapest search that could find the target where a support is known
    fresh: float  # ... where none is: search the room, or find a support and search it


def _cheapest_searches(builder: StateBuilder, look: float) -> _Searches:
    target = builder.task.target
    in_room, on_support = builder.search_cost(target, "in"), builder.search_cost(target, "on")
    supports = [builder.search_cost(s, "in") for s in builder.labels if s != target]
    return _Searches(min(in_room, on_support, look),
                     min(in_room, on_support + min(supports, default=math.inf), look))


def look_cost(body, headings: int) -> float:  # noqa: ANN001 - a RobotBody or None
    """Seconds of one look around: a full turn with a frame at each of `headings`."""
    if body is None:
        return 0.0
    headings = max(2, headings)
    return headings * (body.turn_time(2.0 * math.pi / headings) + body.sensing_time)


def _travel(mind: Mind, field_, here: tuple[float, float],  # noqa: ANN001
            spots: list[tuple[float, float]]) -> float:
    """Metres from the robot to the nearest of `spots`: by grid path where the grid has one,
    else the straight line (a lower bound, like every cost here: a squeeze or a door the
    grid does not show yet may still lead there)."""
    best = math.inf
    for spot in spots:
        cell = mind.grid.cell_of(spot)
        if field_ is not None and mind.grid.contains(cell) and math.isfinite(field_[cell]):
            best = min(best, float(field_[cell]))
        else:
            best = min(best, math.dist(here, spot))
    return best if math.isfinite(best) else 0.0
