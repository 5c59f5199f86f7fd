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

The stopping rule uses the paper's own objective c + R(1 - p). Each option has a lower bound
on what reaching and searching it costs (the way to the nearest of its spots plus the
cheapest way to find the target there: a search, or one look around, since the detector
watches wherever the robot arrives). A continuation that searches a set of options costs at
least the largest of their bounds, and finds the target with at most the probability of
their spaces together. So no continuation is worth more than the best "everything within
cost c": R * P(options with bound <= c) - c over the options' bounds c. When that is not
positive, going on is worse than giving up by the planner's measure, whatever plan it would
make; the give-up names the probability left.
The test is on sets of options, not option by option: exploring reveals several rooms at
once, and ten placeholders of p = 0.09 each are worth going on for although none alone is (a
first version judged each alone and gave up 9 s into an apartment with P = 0.59 left). A
second version set all of P against the cheapest step: a little left in far rooms kept a
robot going beside a nearby room of almost nothing (a development apartment gave up 36 s
later than now).
Every placeholder not given up on counts, short frontiers too: a door first seen edge-on
shows one, and leaving them out gave up on a cereal box behind such a door.
Costs are in the planner's units (`StateBuilder`: metres over the body's speed, search
costs; a look in the body's seconds).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
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
    """The building-level belief: P(target in space not yet searched) and the options;
    `within`: for each option's cost bound c (ascending), P(target in the spaces of the
    options costing at most c)."""

    options: tuple[Option, ...]
    within: tuple[tuple[float, float], ...] = ()

    @property
    def p(self) -> float:
        """P(target in space not yet searched): that within the dearest option's cost."""
        return self.within[-1][1] if self.within else 0.0

    @classmethod
    def of(cls, options: Iterable[Option], mass: Callable[[float], float],
           p_any: Callable[[float], float]) -> Remaining:
        """The belief over `options`, whose spaces are disjoint: their expected counts
        (`mass` of each one's p) add, and `p_any` of a sum is the probability of the spaces
        together (under an uncertain building rate their probabilities are not independent,
        so 1 - prod(1 - p) would overstate it)."""
        options = tuple(options)
        within, total = [], 0.0
        for option in sorted(options, key=lambda o: o.cost):
            total += mass(option.p)
            within.append((option.cost, p_any(total)))
        return cls(options, tuple(within))

    def best(self, reward: float) -> Option | None:
        """The option worth most on its own (for traces)."""
        return max(self.options, key=lambda o: o.value(reward), default=None)

    def cheapest(self) -> Option | None:
        return min(self.options, key=lambda o: o.cost, default=None)

    def worth_going_on(self, reward: float) -> bool:
        """Some continuation may be worth more than giving up: for some cost bound c, R
        times the probability within c exceeds c (an upper bound on any continuation's
        value: see the module's doc)."""
        return any(reward * p > cost for cost, p in self.within)

    def describe(self, reward: float) -> str:
        cheapest = self.cheapest()
        head = f"P(target in space not yet searched) = {self.p:.3g}"
        if cheapest is None:
            return f"{head}; nothing is left to search or explore"
        return (f"{head}; no continuation is worth its cost: reward {reward:g} x P(within "
                f"cost c) is at most c for every c (the cheapest next step: {cheapest.kind} "
                f"{cheapest.name}, cost >= {cheapest.cost:.0f})")


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
    return Remaining.of(options, lambda p: float(cmap.mass(label, p)),
                        lambda m: float(cmap.p_any(label, m)))


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
