"""State builder: the robot's maps and conceptual map as a problem of the AVS domain.

Follows domains/README.md ("What the state builder fills in"). Only a few places enter the
problem (the robot's place, the places placeholders hang off, one place per room), connected
by their shortest path lengths in the place graph, so replans stay small as the map grows.

This module assembles the problem: its objects and atoms, and which labels, categories,
rooms and places enter. Its numbers come from two neighbours: the probability fluents from
the conceptual map (`probabilities.py`) and the prices of moves and searches in the robot's
seconds (`pricing.py`, whose `RELATIONS` is re-exported here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from avs_planner.cp.task import Atom, WorldState
from avs_planner.episode import pricing
from avs_planner.episode.domain import build_problem, planning_problem
from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.mind import Mind
from avs_planner.episode.pricing import RELATIONS, SearchTimes
from avs_planner.episode.probabilities import Probabilities
from avs_planner.pddl import ProbabilisticProblem


@dataclass(frozen=True)
class SearchTask:
    """Report an object of `target`, optionally in a room of `category`.

    A task of several objects (`harness/tasks.py`) searches for one label at a time and
    names the others it still wants as `watch`: the detector looks for them too wherever it
    looks for the target, and one it confirms becomes a known object (reported in its own
    turn). `exclude`: known objects of the target already reported (a task that counts every
    instance): the planner does not see them, so it searches for another one. `mode`: whether
    the task wants all its labels or any one (a DT search over several stops at the first
    confirmed in "any")."""

    target: str
    category: str | None = None
    watch: tuple[str, ...] = ()
    exclude: frozenset[str] = frozenset()
    mode: str = "all"  # the task wants every label (all) or any one of them (any)


@dataclass(frozen=True)
class BuilderConfig:
    """Sizes and static numbers of the problem (search costs/detection rates: §4 of the active
    visual search paper by Göbelbecker et al.)."""

    virtual_rooms: int = 1
    virtual_objects: int = 2
    certain_category: float = 0.9
    max_supports: int = 3
    max_categories: int = 2
    min_probability: float = 0.03
    max_placeholder_tries: int = 2
    max_placeholders: int = 3
    min_frontier_length: float = 0.5
    placeholder_merge: float = 1.0  # m: nearer placeholders are one spot to the planner
    max_failed_room_searches: int = 2
    max_failed_support_searches: int = 2  # then "not on it" is taken as settled
    target_search_cost: tuple[float, float] = (120.0, 10.0)  # in a room, on a support
    support_search_cost: tuple[float, float] = (40.0, 10.0)
    target_detect: tuple[float, float] = (0.5, 0.8)
    support_detect: tuple[float, float] = (0.8, 0.8)
    # every cost in the robot's own seconds, so that the reward R (seconds of robot time a
    # found object is worth) weighs them rightly: a move costs its path length over the
    # body's speed, and a search costs the mean of a prior from the body and the searches
    # of that kind timed in this episode (`observe_search_time`). The prior: the view cones
    # a search is given (up to 6 in a room, 4 around a support: `episode/viewcones.py`),
    # each a drive of `cone_spacing` m, a quarter turn and two frames (a look is two
    # detections). Without a body, the active visual search paper's numbers above, in its
    # own units.
    # On by default since each building's rate is learnt (conceptual_map/.../existence.py): with
    # the active visual search paper's units a room search (120) for p = 0.5 x P(in room) is
    # worth R = 500 only where P > 0.54, and Fig. 3f (development seeds 0-19) gave up 5 times in
    # 20 once one office searched in vain lowered P(markers in the other); priced in seconds, 2
    # in 20, each after the marker's own room was searched and missed. Before that it was off:
    # with exact lambdas it found as many objects but gave up on fewer absent ones.
    seconds: bool = True
    cone_spacing: tuple[float, float] = (2.0, 1.5)  # m between cones: in a room, on a support
    cones_per_search: tuple[int, int] = (6, 4)


@dataclass(frozen=True)
class AvsState:
    """One snapshot as PDDL objects, true atoms, numeric values and goal, plus positions."""

    name: str
    objects: dict[str, list[str]]
    atoms: frozenset[Atom]
    values: dict[Atom, float]
    goal: Atom
    positions: dict[str, tuple[float, float]] = field(default_factory=dict)
    robot_place: str = ""

    def world_state(self) -> WorldState:
        return WorldState(self.atoms, dict(self.values))

    def problem(self) -> ProbabilisticProblem:
        """The full problem (objects, :init, goal)."""
        return build_problem(self.name, self.objects, self.atoms, self.values, self.goal)

    def skeleton(self) -> ProbabilisticProblem:
        """Objects and goal only; plan it with `world_state()` as the initial state."""
        return planning_problem(self.objects, self.goal)

    def to_pddl(self) -> str:
        """The same problem as PDDL text (for `avs domain check`, `avs plan` and traces)."""
        objects = "\n".join(f"    {' '.join(names)} - {t}" for t, names in self.objects.items()
                            if names)
        atoms = "\n".join(f"    ({' '.join(a)})" for a in sorted(self.atoms))
        values = "\n".join(f"    (= ({' '.join(a)}) {_num(v)})"
                           for a, v in sorted(self.values.items()))
        return (f"(define (problem {self.name}) (:domain avs)\n  (:objects\n{objects})\n"
                f"  (:init\n{atoms}\n    (= (total-cost) 0)\n{values})\n"
                f"  (:goal ({' '.join(self.goal)}))\n  (:metric minimize (total-cost)))\n")


def _num(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return text if text not in ("", "-0") else "0"


class StateBuilder:
    """Builds `AvsState`s for one task from a `Mind` (call `build` after every change)."""

    def __init__(self, mind: Mind, task: SearchTask, config: BuilderConfig | None = None):
        self.mind = mind
        self.task = task
        self.config = config or BuilderConfig()
        self._doubted: float | None = None  # the bar `doubt_categories` raised it to
        knowledge = mind.cmap.knowledge
        if task.target not in knowledge.labels:
            raise EpisodeError(f"unknown target label {task.target!r}; the knowledge knows "
                               f"{', '.join(sorted(knowledge.labels))}")
        if task.category is not None and task.category not in knowledge.categories:
            raise EpisodeError(f"unknown room category {task.category!r}; the knowledge knows "
                               f"{', '.join(knowledge.categories)}")
        self.supports = self._supports()
        self.labels = [task.target, *self.supports]
        self.categories = self._likely_categories()
        self._current_categories = list(self.categories)
        self.failed_on: dict[tuple[str, str], int] = {}
        self.failed_in: dict[tuple[str, str], int] = {}
        self.search_times: SearchTimes = {}
        self.revision = 0

    def _supports(self) -> list[str]:
        """The target's support labels by their largest lambda (on them and in them: the
        planner's `on` search of a support looks at both, `viewcones.support_relations`)."""
        knowledge = self.mind.cmap.knowledge
        target = self.task.target
        ranked = sorted(
            ((float(knowledge.support_lambda(target, support).max()), support)
             for support in knowledge.support_relations(target)),
            reverse=True,
        )
        return [s for _, s in ranked[: self.config.max_supports]]

    def drop_support(self) -> str | None:
        """Leave the least likely support label out of future problems (the CP timed out);
        returns it, or None when only the target is left."""
        if not self.supports:
            return None
        dropped = min(self.supports, key=self._support_score)
        self.supports.remove(dropped)
        self.labels.remove(dropped)
        return dropped

    def _support_score(self, support: str) -> float:
        """Expected number of targets on `support`s in the rooms the robot knows, given its
        category beliefs (lambda of the relation times lambda of the support per room)."""
        cmap = self.mind.cmap
        knowledge = cmap.knowledge
        per_category = (knowledge.support_lambda(self.task.target, support)
                        * knowledge.room_lambda(support))
        rooms = [r for r in self.mind.place_map.rooms if cmap.graph.has_room(r)]
        return float(sum(cmap.room_marginal(r) @ per_category for r in rooms))

    def _likely_categories(self) -> list[str]:
        """Categories where the target (directly or on a support) is most expected; the
        others only ever enter as a known room's certain category."""
        knowledge = self.mind.cmap.knowledge
        lam = knowledge.total_room_lambda(self.task.target)
        order = sorted(range(len(knowledge.categories)), key=lambda k: -lam[k])
        chosen = [knowledge.categories[k] for k in order[: self.config.max_categories]]
        if self.task.category is not None and self.task.category not in chosen:
            chosen[-1] = self.task.category
        return chosen

    # ---- the snapshot -----------------------------------------------------------------------

    def build(self) -> AvsState:
        pm = self.mind.place_map
        if pm.current_place is None or not pm.rooms:
            raise EpisodeError("the robot has no place map yet (no scan integrated)")
        self.revision += 1
        rooms = self._relevant_rooms()
        categories = self._categories(rooms)
        places = self._places(rooms)
        placeholders = self._placeholders(places)
        objects = self._known_objects()
        atoms: set[Atom] = set()
        values: dict[Atom, float] = {}
        self._topology(places, placeholders, atoms, values)
        self._rooms(rooms, placeholders, atoms, values)
        self._objects(objects, rooms, atoms, values)
        self._statics(values)
        self._find_on(objects, values)
        names = {
            "place": sorted(places), "placeholder": sorted(placeholders),
            "room": [*rooms, *self._virtual("new-room", self.config.virtual_rooms)],
            "visualobject": [*objects, *self._virtual("new-object", self.config.virtual_objects)],
            "label": list(self.labels), "category": categories,
        }
        positions = {p: pm.places[p].position for p in places}
        positions |= {p: pm.placeholders[p].position for p in placeholders}
        return AvsState(f"episode-{self.revision}", names, frozenset(atoms), values,
                        ("reported", self.task.target), positions, pm.current_place)

    @property
    def certain_category(self) -> float:
        """A room's category believed at least this much is taken as known: the config's
        bar until the loop doubts the categories (`doubt_categories`)."""
        return self.config.certain_category if self._doubted is None else self._doubted

    def doubt_categories(self, threshold: float) -> bool:
        """From now on a room's category counts as known only when believed at least
        `threshold` (raising the bar; False when it is already that high)."""
        if self.certain_category >= threshold:
            return False
        self._doubted = threshold
        return True

    def _categories(self, rooms: list[str]) -> list[str]:
        """The likely categories plus the certain category of any known room."""
        out = list(self.categories)
        for rid in rooms:
            belief = self.mind.cmap.room_category(rid)
            best = max(belief, key=belief.get)
            if belief[best] >= self.certain_category and best not in out:
                out.append(best)
        self._current_categories = out
        return out

    @staticmethod
    def _virtual(prefix: str, k: int) -> list[str]:
        return [f"{prefix}{i}" for i in range(1, k + 1)]

    def _places(self, rooms: list[str]) -> set[str]:
        pm = self.mind.place_map
        chosen = {pm.current_place}
        chosen |= {ph.place for ph in pm.placeholders.values() if ph.place in pm.places}
        for rid in rooms:
            members = sorted(pm.rooms[rid].places & set(pm.places))
            if members:
                centre = np.mean([pm.places[p].position for p in members], axis=0)
                chosen.add(min(members, key=lambda p: math.dist(pm.places[p].position, centre)))
        return {p for p in chosen if pm.room_of(p) in rooms}

    def _placeholders(self, places: set[str]) -> set[str]:
        """Placeholders worth planning with: not given up on, and one per spot (the frontier
        with the most unknown space behind it wins), at most `max_placeholders`. A
        placeholder on free space seen but never visited (a room looked into through its
        door: `conceptual_map/places/unvisited.py`) has no frontier (length 0); it counts
        as one of the shortest frontiers kept, so the planner can go and search that room."""
        pm, tries, cfg = self.mind.place_map, self.mind.tried_placeholders, self.config

        def length(ph) -> float:  # noqa: ANN001 - a Placeholder
            return ph.frontier_length if ph.frontier_length > 0 else cfg.min_frontier_length

        candidates = sorted(
            (ph for pid, ph in pm.placeholders.items()
             if ph.place in places and tries.get(pid, 0) < cfg.max_placeholder_tries
             and pid in self.mind.cmap.placeholders
             and length(ph) >= cfg.min_frontier_length),
            key=lambda ph: (-ph.open_space * length(ph), ph.id),
        )
        kept: list = []
        for ph in candidates:
            if all(math.dist(ph.position, k.position) > cfg.placeholder_merge for k in kept):
                kept.append(ph)
        return {ph.id for ph in kept[: cfg.max_placeholders]}

    def _known_objects(self) -> list[str]:
        return sorted(o.id for o in self.mind.objects.values() if o.label in self.labels
                      and o.id not in self.task.exclude
                      and (o.support is None or o.support in self.mind.objects))

    def _topology(self, places: set[str], placeholders: set[str], atoms: set[Atom],
                  values: dict[Atom, float]) -> None:
        """A star around the robot's place: MOVE from it to every node and back, priced by
        shortest place-graph paths. Plans that chain visits go back through the hub (an
        over-estimate) but the planner's branching stays linear in the map size."""
        pm = self.mind.place_map
        hub = pm.current_place
        nodes = sorted(places | placeholders)
        atoms |= {("at", hub)} | {("visited", p) for p in places}
        lengths = nx.single_source_dijkstra_path_length(pm.graph, hub, weight=self._edge_length)
        for a in nodes:
            for b in nodes:
                values[("move-cost", a, b)] = 0.0
        for node in nodes:
            d = lengths.get(node, math.inf)
            if node == hub or not math.isfinite(d) or self.mind.move_withheld(hub, node):
                continue
            cost = pricing.move_cost(d, self.mind.body, self.config)
            values[("move-cost", hub, node)] = values[("move-cost", node, hub)] = cost
            atoms |= {("connected", hub, node), ("connected", node, hub)}
        for p in nodes:
            atoms.add(("in-room", p, pm.room_of(p)))

    def _edge_length(self, u: str, v: str, data: dict) -> float | None:
        """Place-graph edge length; None (impassable) through a blockage the robot ran into."""
        blockages = self.mind.blockages
        if not blockages.items:
            return data["length"]
        a, b = self._node_position(u), self._node_position(v)
        if a is not None and b is not None and blockages.cutting(a, b) is not None:
            return None
        return data["length"]

    def _node_position(self, node: str) -> tuple[float, float] | None:
        pm = self.mind.place_map
        if node in pm.places:
            return pm.places[node].position
        if node in pm.placeholders:
            return pm.placeholders[node].position
        return None

    def _rooms(self, rooms: list[str], placeholders: set[str], atoms: set[Atom],
               values: dict[Atom, float]) -> None:
        """Known rooms' certain categories, the virtual rooms, and room searches given up
        on; their category and object numbers are `Probabilities`'."""
        virtual = self._virtual("new-room", self.config.virtual_rooms)
        for rid in rooms:
            belief = self.mind.cmap.room_category(rid)
            best = max(belief, key=belief.get)
            if belief[best] >= self.certain_category:
                atoms |= {("has-category", rid, best), ("defined-category", rid)}
        atoms |= {("virtual", rid) for rid in virtual}
        chances, categories = self._probabilities(), self._current_categories
        chances.categories(rooms, virtual, placeholders, categories, values)
        chances.objects_in(self.labels, rooms, virtual, categories, values)
        for label in self.labels:
            for rid in [*rooms, *virtual]:
                if self.failed_in.get((label, rid), 0) >= self.config.max_failed_room_searches:
                    atoms.add(("defined-exists", label, "in", rid))

    def _probabilities(self) -> Probabilities:
        """The probability fluents over the mind's beliefs, with the current settings."""
        return Probabilities(self.mind, self.task, self.config)

    def _relevant_rooms(self) -> list[str]:
        """Rooms worth a planner's thought: the robot's, those holding known objects or
        placeholders, and those that may be of a category where the target is expected."""
        pm, cmap = self.mind.place_map, self.mind.cmap
        keep = {pm.room_of(pm.current_place)}
        keep |= {o.room for o in self.mind.objects.values()}
        keep |= {pm.room_of(ph.place) for ph in pm.placeholders.values() if ph.place}
        for rid in pm.rooms:
            if cmap.graph.has_room(rid):
                belief = cmap.room_category(rid)
                if any(belief[c] >= self.config.min_probability for c in self.categories):
                    keep.add(rid)
        return sorted(r for r in keep if r is not None and cmap.graph.has_room(r))

    def _objects(self, objects: list[str], rooms: list[str], atoms: set[Atom],
                 values: dict[Atom, float]) -> None:
        chances = self._probabilities()
        for oid in objects:
            obj = self.mind.objects[oid]
            atoms |= {("label-of", oid, obj.label), ("detected", oid)}
            if obj.support is None:
                # a found support does not settle "another one in this room": its
                # p-obj-in (the Poisson count still unseen) keeps a second desk possible
                atoms.add(("related", oid, "in", obj.room))
                if obj.label == self.task.target:
                    atoms.add(("defined-exists", obj.label, "in", obj.room))
            else:
                atoms |= {("related", oid, "on", obj.support),
                          ("defined-exists", obj.label, "on", obj.support)}
            for label in self.labels:
                if self.failed_on.get((label, oid), 0) >= self.config.max_failed_support_searches:
                    atoms.add(("defined-exists", label, "on", oid))
            target = self.task.target
            if obj.support is None and chances.settled_on(target, oid):
                atoms.add(("defined-exists", target, "on", oid))
        for oid in self._virtual("new-object", self.config.virtual_objects):
            atoms.add(("virtual", oid))
        for label, rel, loc in self.mind.cones_made:
            if loc in objects or loc in rooms:
                atoms.add(("viewcones", label, rel, loc))

    def _find_on(self, objects: list[str], values: dict[Atom, float]) -> None:
        """`p-find-on`: a search's detection rate times the share of its label on a known
        support still unseen (`Probabilities.find_on`)."""
        virtual = self._virtual("new-object", self.config.virtual_objects)
        self._probabilities().find_on(self.labels, objects, virtual, values)

    def could_hold(self, room: str) -> bool:
        """Under some category, the target may still be in `room` (on its known supports
        included) with at least the planner's `min_probability`, after the looks there so
        far. A room where it may not, whatever its category, cannot enter a plan: reading
        its category again is not worth a visit."""
        return self._probabilities().could_hold(room)

    def travel_speed(self) -> float:
        """Metres per unit of move cost (the body's speed when costs are seconds, else 1)."""
        return pricing.travel_speed(self.mind.body, self.config)

    def cannot_search(self, label: str, relation: str, location: str) -> None:
        """The robot has no view of `location` to search it for `label` from, or the DT
        judged no look there worth its cost: counted as searched as often as it takes to
        settle it (`max_failed_*_searches`)."""
        if relation == "on":
            self.failed_on[(label, location)] = self.config.max_failed_support_searches
        else:
            self.failed_in[(label, location)] = self.config.max_failed_room_searches

    def observe_search_time(self, label: str, relation: str, seconds: float) -> None:
        """A SEARCHFOROBJECT took `seconds` of simulated time (driving to its cones, turning,
        looking): later problems price that kind of search by what it costs this robot."""
        key = (label == self.task.target, relation)
        self.search_times.setdefault(key, []).append(float(seconds))

    def search_cost(self, label: str, relation: str) -> float:
        """The prior cost of a search of this kind, averaged with the ones timed so far
        (the prior counts as one of them; `pricing.search_cost`)."""
        return pricing.search_cost(self.mind.body, self.config, self.search_times,
                                   label == self.task.target, relation)

    def _statics(self, values: dict[Atom, float]) -> None:
        """Per label: each kind of search's cost and detection rate, then `p-obj-on`."""
        cfg = self.config
        chances = self._probabilities()
        for label in self.labels:
            target = label == self.task.target
            detect = cfg.target_detect if target else cfg.support_detect
            for k, rel in enumerate(RELATIONS):
                values[("search-cost", label, rel)] = self.search_cost(label, rel)
                values[("p-detect", label, rel)] = detect[k]
            chances.objects_on(label, self.labels, self._current_categories, values)

    def category_belief(self, room: str) -> dict[str, float]:
        """The room's category belief, rounded, most likely first (for traces)."""
        if room not in self.mind.place_map.rooms or not self.mind.cmap.graph.has_room(room):
            return {}
        belief = self.mind.cmap.room_category(room)
        top = sorted(belief.items(), key=lambda kv: -kv[1])[:3]
        return {c: round(float(p), 3) for c, p in top}
