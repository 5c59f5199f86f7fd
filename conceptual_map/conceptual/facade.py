"""`ConceptualMap`: the one object the place map feeds with events and the planner queries.

Events (rooms, places, links, placeholders, observations) change the chain graph and mark it
dirty; the first query afterwards reruns loopy BP, warm-started from the previous messages.
Ids are plain strings, so any place map can drive it.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from conceptual_map.conceptual.bp import BPResult, BPSettings, PairwiseMRF, loopy_bp
from conceptual_map.conceptual.calibration import PlaceholderCalibration
from conceptual_map.conceptual.chain_graph import ChainGraph, PropertyValue
from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.conceptual.existence import (
    Location,
    ObjectLedger,
    RatePosterior,
    RelatedSpace,
    p_at_least_one,
)
from conceptual_map.conceptual.placeholders import (
    NO_NEW_ROOM,
    PlaceholderEvidence,
    PlaceholderPrediction,
    p_label_beyond,
    predict,
)
from conceptual_map.knowledge import Knowledge, load_knowledge

if TYPE_CHECKING:
    from pgmpy.factors.discrete import DiscreteFactor


class ConceptualMap:
    """Room/placeholder category beliefs and object-existence probabilities (§3 of the active
    visual search paper by Göbelbecker et al.)."""

    def __init__(
        self, knowledge: Knowledge | None = None, settings: BPSettings | None = None
    ) -> None:
        self.knowledge = knowledge if knowledge is not None else load_knowledge()
        self.settings = settings or BPSettings()
        self.graph = ChainGraph(self.knowledge)
        self.objects = ObjectLedger(self.knowledge)
        self._placeholders: dict[str, PlaceholderEvidence] = {}
        self._marginals: dict[str, np.ndarray] = {}
        self._messages: dict[tuple[str, str], np.ndarray] = {}
        self._dirty = True
        self.last_result: BPResult | None = None
        self._rates: dict[str, tuple[BPResult, RatePosterior]] = {}
        self._merged: dict[str, str] = {}  # a merged room -> the room that took it
        # how this building's placeholders ended, correcting the placeholder model
        self.calibration = PlaceholderCalibration(self.knowledge.placeholder)

    # -- structure events ------------------------------------------------------------------

    def add_room(self, room: str) -> None:
        self.graph.add_room(room)
        self._dirty = True

    def add_place(self, place: str, room: str) -> None:
        """Put a place in a room (creating the room); re-adding moves it."""
        self.graph.add_place(place, room)
        self._dirty = True

    def remove_place(self, place: str) -> None:
        self.graph.remove_place(place)
        self._dirty = True

    def connect_rooms(self, a: str, b: str) -> None:
        self.graph.connect(a, b)
        self._dirty = True

    def disconnect_rooms(self, a: str, b: str) -> None:
        self.graph.disconnect(a, b)
        self._dirty = True

    def merge_rooms(self, keep: str, gone: str) -> None:
        """Two rooms turned out to be one: `gone`'s places, links, objects move to `keep`."""
        self.graph.merge_rooms(keep, gone)
        self.objects.move_room(gone, keep)
        self._merged[gone] = keep
        for ph, evidence in self._placeholders.items():
            if evidence.room == gone:
                self._placeholders[ph] = PlaceholderEvidence(
                    keep, evidence.open_space_m2, evidence.p_door
                )
        self._refresh_object_evidence(keep)

    def remove_room(self, room: str) -> None:
        """Delete a room with its places, links and placeholders (not one holding objects)."""
        self.graph.require_room(room)
        held = [r.object_id for r in self.objects.objects.values() if r.room == room]
        if held:
            raise ConceptualError(f"room {room!r} holds objects {held}; merge it instead")
        self.graph.remove_room(room)
        self.objects.forget_room(room)
        for ph in [ph for ph, ev in self._placeholders.items() if ev.room == room]:
            del self._placeholders[ph]
        self._dirty = True

    def current_room(self, room: str) -> str | None:
        """The room `room` is now: itself, the room it was merged into (a search that began
        in it may end after the map merged it), or None if it was removed."""
        seen = set()
        while not self.graph.has_room(room):
            if room in seen or room not in self._merged:
                return None
            seen.add(room)
            room = self._merged[room]
        return room

    # -- placeholders ----------------------------------------------------------------------

    @property
    def placeholders(self) -> Mapping[str, PlaceholderEvidence]:
        return MappingProxyType(self._placeholders)

    def add_placeholder(
        self, placeholder: str, room: str, open_space_m2: float = 0.0, p_door: float = 0.0
    ) -> None:
        """A frontier placeholder of `room`, with open space behind it and door belief."""
        self.graph.require_room(room)
        self._placeholders[placeholder] = PlaceholderEvidence(room, open_space_m2, p_door)

    def update_placeholder(
        self,
        placeholder: str,
        *,
        room: str | None = None,
        open_space_m2: float | None = None,
        p_door: float | None = None,
    ) -> None:
        old = self._placeholder(placeholder)
        self.add_placeholder(
            placeholder,
            room if room is not None else old.room,
            old.open_space_m2 if open_space_m2 is None else open_space_m2,
            old.p_door if p_door is None else p_door,
        )

    def observe_placeholder_outcome(self, evidence: PlaceholderEvidence,
                                    led_to_new_room: bool) -> None:
        """A placeholder that vanished with `evidence` led to a new room, or did not (the
        robot's own map tells: `avs_planner/episode/placeholder_outcomes.py`). The placeholders
        still open are predicted with the building's outcomes so far (`calibration.py`)."""
        self.calibration.record(evidence, led_to_new_room)

    def remove_placeholder(self, placeholder: str) -> None:
        self._placeholder(placeholder)
        del self._placeholders[placeholder]

    def _placeholder(self, placeholder: str) -> PlaceholderEvidence:
        try:
            return self._placeholders[placeholder]
        except KeyError:
            raise ConceptualError(f"unknown placeholder {placeholder!r}") from None

    # -- evidence --------------------------------------------------------------------------

    def observe_property(self, place: str, kind: str, value: PropertyValue) -> None:
        """Property evidence (size, shape, appearance, ...) at a place; replaces older evidence."""
        self.graph.observe_property(place, kind, value)
        self._dirty = True

    def observe_room_property(self, room: str, kind: str, value: PropertyValue) -> None:
        """Property evidence about a whole room (e.g. size from its area); replaces older."""
        self.graph.observe_room_property(room, kind, value)
        self._dirty = True

    def observe_object(
        self,
        label: str,
        room: str,
        on: str | None = None,
        *,
        inside: str | None = None,
        object_id: str | None = None,
    ) -> str:
        """A detected object in `room`, optionally on/inside a known object; returns its id."""
        self.graph.require_room(room)
        if on is not None and inside is not None:
            raise ConceptualError(f"object {label!r} cannot be both on {on!r} and in {inside!r}")
        relation = "on" if on is not None else "in" if inside is not None else None
        record = self.objects.add(label, room, relation, on or inside, object_id)
        self._refresh_object_evidence(room)
        return record.object_id

    def move_object(self, object_id: str, room: str) -> None:
        """A detected object stands in `room`, not where it was credited (the map has since
        parted that space into rooms): it moves with what stands on it, and both rooms'
        object evidence follows."""
        self.graph.require_room(room)
        old = self.objects.move_object(object_id, room)
        if old != room:
            self._refresh_object_evidence(room)
            if self.graph.has_room(old):
                self._refresh_object_evidence(old)

    def forget_object(self, object_id: str) -> None:
        """A detected object proved false (not seen again where it was): as if never seen."""
        record = self.objects.remove(object_id)
        self._refresh_object_evidence(record.room)

    def observe_search(
        self, label: str, location: Location | tuple[str, str], coverage: float, p_detect: float
    ) -> None:
        """A search for `label` looked through `coverage` of `location` (x detection
        probability); if nothing was found it is also evidence about the room's category.
        A room merged since is the room that took it (`current_room`)."""
        location = self._current(_as_location(location))
        self.objects.record_search(label, location, coverage, p_detect)
        self._refresh_object_evidence(self._room_of(location))

    def observe_glimpses(
        self, label: str, location: Location | tuple[str, str], share: float
    ) -> None:
        """Frames taken in passing have looked at `share` of `location` (x detection
        probability) without seeing `label`; replaces the last share given for it."""
        location = self._current(_as_location(location))
        self.objects.record_glimpses(label, location, share)
        self._refresh_object_evidence(self._room_of(location))

    def _current(self, location: Location) -> Location:
        if isinstance(location, str):
            return self.current_room(location) or location  # removed: require_room names it
        return location

    def _refresh_object_evidence(self, room: str) -> None:
        self.graph.set_room_evidence(room, self.objects.room_likelihood(room))
        self._dirty = True

    def _room_of(self, location: Location) -> str:
        room = self.objects.room_of(location)
        self.graph.require_room(room)
        return room

    # -- inference -------------------------------------------------------------------------

    def update(self, force: bool = False, cold: bool = False) -> BPResult:
        """Rerun loopy BP if anything changed (or `force`); returns the run's result.

        `cold` also recomputes every room's unary and starts BP from uniform messages.
        """
        if cold:
            self.graph.invalidate()
            self._messages = {}
        if self._dirty or force or cold or self.last_result is None:
            mrf, rooms = self.graph.compile()
            result = loopy_bp(mrf, self.settings, self._warm_start(mrf, rooms))
            self._store(mrf, rooms, result)
        assert self.last_result is not None
        return self.last_result

    def _warm_start(self, mrf: PairwiseMRF, rooms: list[str]) -> np.ndarray | None:
        if not self._messages or len(mrf.edges) == 0:
            return None
        keys = _directed_keys(mrf, rooms)
        uniform = np.full(len(self.knowledge.categories), 1.0 / len(self.knowledge.categories))
        return np.array([self._messages.get(key, uniform) for key in keys])

    def _store(self, mrf: PairwiseMRF, rooms: list[str], result: BPResult) -> None:
        self._marginals = dict(zip(rooms, result.marginals, strict=True))
        keys = _directed_keys(mrf, rooms)
        self._messages = dict(zip(keys, result.messages, strict=True))
        self.last_result = result
        self._dirty = False

    def room_marginal(self, room: str) -> np.ndarray:
        """P_category(room) as a vector in `knowledge.categories` order."""
        self.graph.require_room(room)
        self.update()
        return self._marginals[room]

    def room_category(self, room: str) -> dict[str, float]:
        """P_category(room)."""
        return _named(self.knowledge.categories, self.room_marginal(room))

    def placeholder_prediction(self, placeholder: str) -> PlaceholderPrediction:
        """What lies behind `placeholder`: the hypotheses of `placeholders.py`, weighted as
        this building's placeholders so far calibrate them (`calibration.py`)."""
        evidence = self._placeholder(placeholder)
        return predict(self.knowledge, self.room_marginal(evidence.room), evidence,
                       self.calibration.weights(evidence))

    def placeholder_category(self, placeholder: str) -> dict[str, float]:
        """P(placeholder leads to a new room of each category), plus `"none"`: no new room."""
        prediction = self.placeholder_prediction(placeholder)
        return {**prediction.any_room, NO_NEW_ROOM: prediction.no_new_room}

    # -- existence ---------------------------------------------------------------------------

    def rate_posterior(self, label: str) -> RatePosterior | None:
        """This building's rate multiplier for `label` after everything seen (None when the
        knowledge takes its lambdas as exact): Gamma(a + found, a + exposure), the exposure
        being what the looks for `label` would have seen, over each room's category belief
        (`ObjectLedger.searched_lambda`)."""
        shape = self.knowledge.rate_shape
        if shape is None:
            return None
        result = self.update()
        cached = self._rates.get(label)
        if cached is not None and cached[0] is result:
            return cached[1]
        exposure = sum(float(self.room_marginal(room) @ self.objects.searched_lambda(label, room))
                       for room in self.objects.looked_rooms(label) if self.graph.has_room(room))
        posterior = RatePosterior.after(shape, self.objects.found(label), exposure)
        self._rates[label] = (result, posterior)
        return posterior

    def p_any(self, label: str, lam: np.ndarray | float) -> np.ndarray:
        """P(at least one `label`) where the knowledge expects `lam` of them, in this building
        (Poisson when the lambdas are exact, else negative binomial: `rate_posterior`)."""
        posterior = self.rate_posterior(label)
        return p_at_least_one(lam) if posterior is None else posterior.p_any(lam)

    def mass(self, label: str, p: np.ndarray | float) -> np.ndarray:
        """The expected count whose `p_any` is `p`: to add the probabilities of disjoint
        spaces, add their masses (under a shared rate they are not independent)."""
        posterior = self.rate_posterior(label)
        if posterior is None:
            return -np.log1p(-np.clip(np.asarray(p, dtype=float), 0.0, 1.0 - 1e-12))
        return posterior.mass(p)

    def p_object_at(
        self, label: str, location: Location | tuple[str, str], include_sublocations: bool = True,
        *, another: bool = False,
    ) -> float:
        """P(ObjectAt L): at least one `label` at a room (with its related spaces) or related space.

        Sums, under each room category, the lambdas left unseen by searches over L and (for a
        room) the in/on spaces of its known objects that the knowledge lists for `label`, then
        averages 1 - exp(-lambda) over the category belief. `another`: one more beyond those
        found (a task counting every instance): found ones do not make it 1, the unseen
        lambda alone counts (Poisson counts in disjoint parts are independent).
        """
        location = _as_location(location)
        residual = self._residual(label, location, include_sublocations, another)
        if residual is None:
            return 1.0
        return float(self.room_marginal(self._room_of(location)) @ self.p_any(label, residual))

    def p_object_at_per_category(
        self, label: str, location: Location | tuple[str, str], include_sublocations: bool = True,
        *, another: bool = False,
    ) -> np.ndarray:
        """`p_object_at` under each room category (`knowledge.categories` order), before
        the category belief averages it: 1 where a `label` was seen there (unless
        `another`, as in `p_object_at`)."""
        residual = self._residual(label, _as_location(location), include_sublocations, another)
        if residual is None:
            return np.ones(len(self.knowledge.categories))
        return self.p_any(label, residual)

    def _residual(self, label: str, location: Location, include_sublocations: bool,
                  another: bool = False) -> np.ndarray | None:
        """Per category, the lambda of `label` left unseen by searches over the location
        (and a room's in/on spaces); None where a `label` was seen there (unless `another`:
        then the unseen lambda, whatever was found)."""
        room = self._room_of(location)
        places = [location]
        if include_sublocations and not isinstance(location, RelatedSpace):
            places += self.objects.sublocations(room, label)
        if not another and any(self.objects.count(place, label) for place in places):
            return None
        return sum(
            self.objects.location_lambda(label, place) * self.objects.remaining(place, label)
            for place in places
        )

    def p_object_in_room_per_category(self, label: str, room: str) -> np.ndarray:
        """P(at least one `label` in `room` outside its known objects' spaces) under each
        room category (`knowledge.categories` order): the room itself and the supports not
        found yet, after the looks so far (`ObjectLedger.unexplained_lambda`). Objects of
        `label` already found do not count: this is about one more."""
        self.graph.require_room(room)
        return self.p_any(label, self.objects.unexplained_lambda(label, room))

    def p_unsearched(self, label: str, room: str) -> float:
        """P(at least one `label` in `room` where no look has ruled it out: the room, its
        supports not found yet and its known objects' spaces), over the category belief.
        The building-level stopping rule sums this over rooms and placeholders."""
        self.graph.require_room(room)
        lam = self.objects.unsearched_lambda(label, room)
        return float(self.room_marginal(room) @ self.p_any(label, lam))

    def p_beyond_placeholder(self, label: str, placeholder: str) -> float:
        """P(at least one `label` in the new rooms a placeholder may lead to)
        (`placeholders.p_label_beyond`: the exploration hypotheses and their categories)."""
        evidence = self._placeholder(placeholder)
        posterior = self.rate_posterior(label)
        return p_label_beyond(self.knowledge, self.room_marginal(evidence.room), evidence,
                              self.objects.fresh_room_lambda(label),
                              None if posterior is None else posterior.p_none,
                              self.calibration.weights(evidence))

    def p_object_at_category(
        self, label: str, category: str, support_label: str | None = None, relation: str = "on"
    ) -> float:
        """P(ObjectAt L^C): default knowledge for a room of `category` (or `relation` a support)."""
        try:
            column = self.knowledge.category_index(category)
            if support_label is None:
                lam = self.knowledge.room_lambda(label)
            else:
                lam = self.knowledge.relation_lambda_of(label, relation, support_label)
        except KeyError as exc:
            raise ConceptualError(str(exc.args[0])) from None
        return float(self.p_any(label, lam[column]))

    def factors(
        self, explicit_properties: bool = False, merged: bool = False
    ) -> list[DiscreteFactor]:
        """The current chain graph as pgmpy factors (see `ChainGraph.factors`)."""
        return self.graph.factors(explicit_properties, merged)


def _as_location(location: Location | tuple[str, str]) -> Location:
    if isinstance(location, str | RelatedSpace):
        return location
    if isinstance(location, tuple) and len(location) == 2:
        return RelatedSpace(*location)
    raise ConceptualError(f"location must be a room id or (relation, object id), got {location!r}")


def _directed_keys(mrf: PairwiseMRF, rooms: list[str]) -> list[tuple[str, str]]:
    forward = [(rooms[a], rooms[b]) for a, b in mrf.edges]
    return forward + [(b, a) for a, b in forward]


def _named(names: tuple[str, ...], values: np.ndarray) -> dict[str, float]:
    return dict(zip(names, values.tolist(), strict=True))
