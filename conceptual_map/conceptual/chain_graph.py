"""The chain graph of seed 003 §3: room categories, place properties, phi_rc between rooms.

One category variable per room; each observed place property is a directed factor
P(value | category of the place's room) (a pgmpy `DiscreteFactor`, reduced by the evidence);
adjacent rooms share an undirected phi_rc factor. Changed incrementally by events; `compile()`
turns it into the pairwise network loopy BP runs on, recomputing only rooms that changed.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np
from pgmpy.factors.discrete import DiscreteFactor

from conceptual_map.conceptual.bp import PairwiseMRF
from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.knowledge import Knowledge

PropertyValue = str | Mapping[str, float]
"""A hard property value, or soft evidence: likelihood weight per value (e.g. classifier output)."""

_CATEGORY = "category"


def category_variable(room: str) -> str:
    """Name of the category variable of `room` in exported pgmpy factors."""
    return f"category[{room}]"


def property_variable(place: str, kind: str) -> str:
    """Name of the `kind` property variable of `place` in exported pgmpy factors."""
    return f"{kind}[{place}]"


class ChainGraph:
    """Rooms, places, room adjacency and property evidence, with a per-room unary cache."""

    def __init__(self, knowledge: Knowledge) -> None:
        self.knowledge = knowledge
        self._places_of: dict[str, set[str]] = {}
        self._room_of: dict[str, str] = {}
        self._neighbours: dict[str, set[str]] = {}
        self._evidence: dict[str, dict[str, np.ndarray]] = {}
        self._likelihood: dict[str, dict[str, DiscreteFactor]] = {}
        self._room_evidence: dict[str, np.ndarray] = {}
        self._unary: dict[str, np.ndarray] = {}

    # -- structure -------------------------------------------------------------------------

    @property
    def rooms(self) -> list[str]:
        """Room ids in insertion order (the node order of `compile()`)."""
        return list(self._places_of)

    def has_room(self, room: str) -> bool:
        return room in self._places_of

    def room_of(self, place: str) -> str:
        """Room holding `place`; ConceptualError if the place is unknown."""
        try:
            return self._room_of[place]
        except KeyError:
            raise ConceptualError(f"unknown place {place!r}") from None

    def places_of(self, room: str) -> frozenset[str]:
        self.require_room(room)
        return frozenset(self._places_of[room])

    def neighbours(self, room: str) -> frozenset[str]:
        self.require_room(room)
        return frozenset(self._neighbours[room])

    def require_room(self, room: str) -> None:
        if room not in self._places_of:
            raise ConceptualError(f"unknown room {room!r}")

    def add_room(self, room: str) -> None:
        """Add an empty room (no-op if it exists)."""
        if not isinstance(room, str) or not room:
            raise ConceptualError(f"room id must be a non-empty string, got {room!r}")
        if room not in self._places_of:
            self._places_of[room] = set()
            self._neighbours[room] = set()
            self._touch(room)

    def add_place(self, place: str, room: str) -> None:
        """Put `place` in `room` (creating the room); moves the place if it was elsewhere."""
        if not isinstance(place, str) or not place:
            raise ConceptualError(f"place id must be a non-empty string, got {place!r}")
        self.add_room(room)
        old = self._room_of.get(place)
        if old is not None:
            self._places_of[old].discard(place)
            self._touch(old)
        self._room_of[place] = room
        self._places_of[room].add(place)
        self._touch(room)

    def remove_place(self, place: str) -> None:
        room = self.room_of(place)
        self._places_of[room].discard(place)
        del self._room_of[place]
        self._evidence.pop(place, None)
        self._likelihood.pop(place, None)
        self._touch(room)

    def connect(self, a: str, b: str) -> None:
        """Undirected phi_rc link between two different known rooms."""
        self.require_room(a)
        self.require_room(b)
        if a == b:
            raise ConceptualError(f"cannot connect room {a!r} to itself")
        self._neighbours[a].add(b)
        self._neighbours[b].add(a)

    def disconnect(self, a: str, b: str) -> None:
        self.require_room(a)
        self.require_room(b)
        self._neighbours[a].discard(b)
        self._neighbours[b].discard(a)

    def merge_rooms(self, keep: str, gone: str) -> None:
        """Move `gone`'s places and links to `keep` and delete `gone` (and its room evidence)."""
        self.require_room(keep)
        self.require_room(gone)
        if keep == gone:
            raise ConceptualError(f"cannot merge room {keep!r} with itself")
        for place in list(self._places_of[gone]):
            self.add_place(place, keep)
        for other in list(self._neighbours[gone]):
            self.disconnect(gone, other)
            if other != keep:
                self.connect(keep, other)
        self.remove_room(gone)

    def remove_room(self, room: str) -> None:
        """Delete a room, its places and links."""
        self.require_room(room)
        for place in list(self._places_of[room]):
            self.remove_place(place)
        for other in list(self._neighbours[room]):
            self.disconnect(room, other)
        for table in (self._places_of, self._neighbours, self._room_evidence, self._unary):
            table.pop(room, None)

    def _touch(self, room: str) -> None:
        self._unary.pop(room, None)

    # -- evidence --------------------------------------------------------------------------

    def observe_property(self, place: str, kind: str, value: PropertyValue) -> None:
        """Evidence on a place property; replaces earlier evidence of that kind at the place."""
        room = self.room_of(place)
        model = self.knowledge.properties.get(kind)
        if model is None:
            known = ", ".join(self.knowledge.properties)
            raise ConceptualError(f"unknown property kind {kind!r} (known: {known})")
        weights = _evidence_vector(model.values, kind, value)
        self._evidence.setdefault(place, {})[kind] = weights
        self._likelihood.setdefault(place, {})[kind] = _reduced_property_factor(
            model.table, kind, weights
        )
        self._touch(room)

    def set_room_evidence(self, room: str, likelihood: np.ndarray | float) -> None:
        """Replace the object/search likelihood vector over `room`'s category (owned by caller)."""
        self.require_room(room)
        vector = np.broadcast_to(np.asarray(likelihood, dtype=float), self.knowledge.prior.shape)
        self._room_evidence[room] = vector.copy()
        self._touch(room)

    # -- compiled views --------------------------------------------------------------------

    def unary(self, room: str) -> np.ndarray:
        """Normalised product of prior, property likelihoods and object evidence of `room`."""
        cached = self._unary.get(room)
        if cached is None:
            cached = self._compute_unary(room)
            self._unary[room] = cached
        return cached

    def _compute_unary(self, room: str) -> np.ndarray:
        self.require_room(room)
        log_unary = np.log(self.knowledge.prior).copy()
        with np.errstate(divide="ignore"):
            for factor in self._room_factors(room):
                log_unary += np.log(factor)
        top = log_unary.max()
        if not np.isfinite(top):
            return np.full_like(log_unary, 1.0 / log_unary.size)
        unary = np.exp(log_unary - top)
        return unary / unary.sum()

    def _room_factors(self, room: str) -> Iterable[np.ndarray]:
        for place in self._places_of[room]:
            for factor in self._likelihood.get(place, {}).values():
                yield factor.values
        if room in self._room_evidence:
            yield self._room_evidence[room]

    def compile(self) -> tuple[PairwiseMRF, list[str]]:
        """The pairwise network over room categories (rooms in `self.rooms` order)."""
        rooms = self.rooms
        index = {room: i for i, room in enumerate(rooms)}
        states = len(self.knowledge.categories)
        unary = np.array([self.unary(room) for room in rooms]).reshape(-1, states)
        pairs = [(index[a], index[b]) for a in rooms for b in self._neighbours[a]]
        edges = np.array([p for p in pairs if p[0] < p[1]], dtype=np.int64).reshape(-1, 2)
        pairwise = np.broadcast_to(self.knowledge.connectivity, (len(edges), states, states))
        return PairwiseMRF(unary, edges, pairwise), rooms

    def factors(self, explicit_properties: bool = False) -> list[DiscreteFactor]:
        """The chain graph as pgmpy factors (for exact inference and inspection).

        With `explicit_properties`, every observed place property is its own variable with the
        full P(value | category) factor plus an evidence factor; otherwise the reduced form.
        """
        states = len(self.knowledge.categories)
        order = {room: i for i, room in enumerate(self.rooms)}
        factors = []
        for room in order:
            variable = category_variable(room)
            factors.append(DiscreteFactor([variable], [states], self.knowledge.prior.copy()))
            factors.extend(self._property_factors(room, explicit_properties))
            if room in self._room_evidence:
                factors.append(DiscreteFactor([variable], [states], self._room_evidence[room]))
            for other in self._neighbours[room]:
                if order[other] > order[room]:
                    factors.append(self._phi_factor(room, other))
        return factors

    def _property_factors(self, room: str, explicit: bool) -> list[DiscreteFactor]:
        variable, states = category_variable(room), len(self.knowledge.categories)
        result = []
        for place in sorted(self._places_of[room]):
            for kind, weights in self._evidence.get(place, {}).items():
                if not explicit:
                    values = self._likelihood[place][kind].values
                    result.append(DiscreteFactor([variable], [states], values.copy()))
                    continue
                prop = property_variable(place, kind)
                table = self.knowledge.properties[kind].table
                result.append(DiscreteFactor([variable, prop], list(table.shape), table.copy()))
                result.append(DiscreteFactor([prop], [len(weights)], weights.copy()))
        return result

    def _phi_factor(self, a: str, b: str) -> DiscreteFactor:
        phi = self.knowledge.connectivity
        return DiscreteFactor(
            [category_variable(a), category_variable(b)], list(phi.shape), phi.copy()
        )


def _evidence_vector(values: tuple[str, ...], kind: str, value: PropertyValue) -> np.ndarray:
    """One-hot for a hard value, the given non-negative weights for soft evidence."""
    if isinstance(value, str):
        if value not in values:
            raise ConceptualError(f"unknown {kind} value {value!r} (known: {', '.join(values)})")
        return np.eye(len(values))[values.index(value)]
    if not isinstance(value, Mapping):
        raise ConceptualError(f"{kind} evidence must be a value name or a mapping, got {value!r}")
    unknown = sorted(set(value) - set(values))
    if unknown:
        raise ConceptualError(f"unknown {kind} value {unknown[0]!r} in soft evidence")
    weights = np.array([float(value.get(v, 0.0)) for v in values])
    if not np.all(np.isfinite(weights)) or weights.min() < 0 or weights.sum() <= 0:
        raise ConceptualError(f"{kind} soft evidence needs non-negative weights, got {value!r}")
    return weights


def _reduced_property_factor(
    table: np.ndarray, kind: str, weights: np.ndarray
) -> DiscreteFactor:
    """P(value | category) times the evidence on the value, summed over the value."""
    cpd = DiscreteFactor([_CATEGORY, kind], list(table.shape), table)
    evidence = DiscreteFactor([kind], [len(weights)], weights)
    return cpd.product(evidence, inplace=False).marginalize([kind], inplace=False)
