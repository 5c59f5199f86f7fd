"""The chain graph of §3 of Göbelbecker et al., "A Planning Approach to Active Visual Search in
Large Environments": room categories, place properties, phi_rc between rooms.

One category variable per room; each observed place property is a directed factor
P(value | category of the place's room), reduced by the evidence to a likelihood vector over
the category; adjacent rooms share an undirected phi_rc factor. Changed incrementally by
events; `compile()` turns it into the pairwise network loopy BP runs on, recomputing only
rooms that changed. `factors()` exports it as pgmpy `DiscreteFactor`s (exact inference,
inspection): pgmpy is imported there only, as it takes ~0.5 s to import and an episode never
needs it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from conceptual_map.conceptual.bp import PairwiseMRF
from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.knowledge import Knowledge

if TYPE_CHECKING:
    from pgmpy.factors.discrete import DiscreteFactor

PropertyValue = str | Mapping[str, float]
"""A hard property value, or soft evidence: likelihood weight per value (e.g. classifier output)."""

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
        self._likelihood: dict[str, dict[str, np.ndarray]] = {}  # reduced, over the category
        self._place_log: dict[str, np.ndarray] = {}
        self._room_evidence: dict[str, np.ndarray] = {}
        self._room_properties: dict[str, dict[str, tuple[np.ndarray, np.ndarray]]] = {}
        self._unary: dict[str, np.ndarray] = {}

    # -- structure -------------------------------------------------------------------------

    @property
    def rooms(self) -> list[str]:
        """Room ids in insertion order (the node order of `compile()`)."""
        return list(self._places_of)

    def has_room(self, room: str) -> bool:
        return room in self._places_of

    def has_place(self, place: str) -> bool:
        return place in self._room_of

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
        self._place_log.pop(place, None)
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
        tables = (self._places_of, self._neighbours, self._room_evidence, self._room_properties,
                  self._unary)
        for table in tables:
            table.pop(room, None)

    def _touch(self, room: str) -> None:
        self._unary.pop(room, None)

    # -- evidence --------------------------------------------------------------------------

    def observe_property(self, place: str, kind: str, value: PropertyValue) -> None:
        """Evidence on a place property; replaces earlier evidence of that kind at the place."""
        room = self.room_of(place)
        weights, likelihood = self._property_evidence(kind, value)
        self._evidence.setdefault(place, {})[kind] = weights
        self._likelihood.setdefault(place, {})[kind] = likelihood
        with np.errstate(divide="ignore"):
            self._place_log[place] = sum(
                (np.log(f) for f in self._likelihood[place].values()),
                start=np.zeros(len(self.knowledge.categories)),
            )
        self._touch(room)

    def place_evidence(self) -> dict[str, dict[str, dict[str, float]]]:
        """Each place's property evidence as soft weights per value (`observe_property`
        takes them back): what a later run keeps of what the place classifier said."""
        out: dict[str, dict[str, dict[str, float]]] = {}
        for place, kinds in self._evidence.items():
            for kind, weights in kinds.items():
                values = self.knowledge.properties[kind].values
                out.setdefault(place, {})[kind] = {
                    v: float(w) for v, w in zip(values, weights, strict=True) if w > 0}
        return out

    def observe_room_property(self, room: str, kind: str, value: PropertyValue) -> None:
        """Evidence on a property of a whole room (e.g. its area from the place map).

        Replaces earlier room-level evidence of that kind; dropped when the room is merged away.
        """
        self.require_room(room)
        self._room_properties.setdefault(room, {})[kind] = self._property_evidence(kind, value)
        self._touch(room)

    def _property_evidence(
        self, kind: str, value: PropertyValue
    ) -> tuple[np.ndarray, np.ndarray]:
        """The evidence weights over the values and the likelihood over the category."""
        model = self.knowledge.properties.get(kind)
        if model is None:
            known = ", ".join(self.knowledge.properties)
            raise ConceptualError(f"unknown property kind {kind!r} (known: {known})")
        weights = _evidence_vector(model.values, kind, value)
        return weights, _reduced_likelihood(model.table, weights)

    def set_room_evidence(self, room: str, likelihood: np.ndarray | float) -> None:
        """Replace the object/search likelihood vector over `room`'s category (owned by caller)."""
        self.require_room(room)
        vector = np.broadcast_to(np.asarray(likelihood, dtype=float), self.knowledge.prior.shape)
        self._room_evidence[room] = vector.copy()
        self._touch(room)

    # -- compiled views --------------------------------------------------------------------

    def invalidate(self) -> None:
        """Drop every cached unary (the next `compile()` recomputes all rooms)."""
        self._unary.clear()

    def unary(self, room: str) -> np.ndarray:
        """Normalised product of prior, property likelihoods and object evidence of `room`."""
        self.require_room(room)
        if room not in self._unary:
            self._refresh_unaries([room])
        return self._unary[room]

    def _refresh_unaries(self, rooms: list[str]) -> None:
        """Recompute the unaries of `rooms` in one vectorised pass (sums of log-likelihoods)."""
        index = {room: i for i, room in enumerate(rooms)}
        log_unary = np.tile(np.log(self.knowledge.prior), (len(rooms), 1))
        owners = [index[self._room_of[p]] for r in rooms for p in self._places_of[r]
                  if p in self._place_log]
        if owners:
            logs = [self._place_log[p] for r in rooms for p in self._places_of[r]
                    if p in self._place_log]
            np.add.at(log_unary, owners, np.array(logs))
        with np.errstate(divide="ignore"):
            for room in rooms:
                for _weights, likelihood in self._room_properties.get(room, {}).values():
                    log_unary[index[room]] += np.log(likelihood)
                if room in self._room_evidence:
                    log_unary[index[room]] += np.log(self._room_evidence[room])
        for room, row in zip(rooms, _row_softmax(log_unary), strict=True):
            self._unary[room] = row

    def compile(self) -> tuple[PairwiseMRF, list[str]]:
        """The pairwise network over room categories (rooms in `self.rooms` order)."""
        rooms = self.rooms
        stale = [room for room in rooms if room not in self._unary]
        if stale:
            self._refresh_unaries(stale)
        index = {room: i for i, room in enumerate(rooms)}
        states = len(self.knowledge.categories)
        unary = np.array([self._unary[room] for room in rooms]).reshape(-1, states)
        pairs = [(index[a], index[b]) for a in rooms for b in self._neighbours[a]]
        edges = np.array([p for p in pairs if p[0] < p[1]], dtype=np.int64).reshape(-1, 2)
        pairwise = np.broadcast_to(self.knowledge.connectivity, (len(edges), states, states))
        return PairwiseMRF(unary, edges, pairwise), rooms

    def factors(
        self, explicit_properties: bool = False, merged: bool = False
    ) -> list[DiscreteFactor]:
        """The chain graph as pgmpy factors (for exact inference and inspection).

        With `explicit_properties`, every observed place property is its own variable with the
        full P(value | category) factor plus an evidence factor; otherwise the reduced form
        (likelihood vectors over the room category, scaled to a maximum of 1). `merged` gives
        one unary per room instead (all its evidence multiplied), which keeps exact inference
        on large maps from underflowing.
        """
        states = len(self.knowledge.categories)
        order = {room: i for i, room in enumerate(self.rooms)}
        factors = []
        for room in order:
            variable = category_variable(room)
            if merged:
                factors.append(_factor([variable], [states], _max_normalised(self.unary(room))))
            else:
                factors.extend(self._room_unaries(room, explicit_properties))
            for other in self._neighbours[room]:
                if order[other] > order[room]:
                    factors.append(self._phi_factor(room, other))
        return factors

    def _room_unaries(self, room: str, explicit: bool) -> list[DiscreteFactor]:
        variable, states = category_variable(room), len(self.knowledge.categories)
        factors = [_factor([variable], [states], self.knowledge.prior.copy())]
        factors.extend(self._property_factors(room, explicit))
        for kind, (weights, likelihood) in self._room_properties.get(room, {}).items():
            factors.extend(self._evidence_factors(room, f"room:{room}", kind, weights,
                                                  likelihood, explicit))
        if room in self._room_evidence:
            values = _max_normalised(self._room_evidence[room])
            factors.append(_factor([variable], [states], values))
        return factors

    def _property_factors(self, room: str, explicit: bool) -> list[DiscreteFactor]:
        result = []
        for place in sorted(self._places_of[room]):
            for kind, weights in self._evidence.get(place, {}).items():
                likelihood = self._likelihood[place][kind]
                result += self._evidence_factors(room, place, kind, weights, likelihood,
                                                 explicit)
        return result

    def _evidence_factors(
        self,
        room: str,
        holder: str,
        kind: str,
        weights: np.ndarray,
        reduced: np.ndarray,
        explicit: bool,
    ) -> list[DiscreteFactor]:
        """Reduced likelihood over the room category, or the CPD plus an evidence factor."""
        variable, states = category_variable(room), len(self.knowledge.categories)
        if not explicit:
            return [_factor([variable], [states], _max_normalised(reduced))]
        prop = property_variable(holder, kind)
        table = self.knowledge.properties[kind].table
        return [_factor([variable, prop], list(table.shape), table.copy()),
                _factor([prop], [len(weights)], weights.copy())]

    def _phi_factor(self, a: str, b: str) -> DiscreteFactor:
        phi = self.knowledge.connectivity
        return _factor([category_variable(a), category_variable(b)], list(phi.shape), phi.copy())


def _row_softmax(log_values: np.ndarray) -> np.ndarray:
    """Rows exp-normalised; a row with no possible state (contradiction) becomes uniform."""
    top = log_values.max(axis=1, keepdims=True)
    finite = np.isfinite(top)
    values = np.exp(log_values - np.where(finite, top, 0.0))
    values[~finite[:, 0]] = 1.0
    return values / values.sum(axis=1, keepdims=True)


def _max_normalised(values: np.ndarray) -> np.ndarray:
    """Scaled so the largest entry is 1: same evidence, no underflow in long products."""
    top = values.max()
    return values / top if top > 0 else values.copy()


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
    try:
        weights = np.array([float(value.get(v, 0.0)) for v in values])
    except (TypeError, ValueError):
        raise ConceptualError(f"{kind} soft evidence needs numbers, got {value!r}") from None
    if not np.all(np.isfinite(weights)) or weights.min() < 0 or weights.sum() <= 0:
        raise ConceptualError(f"{kind} soft evidence needs non-negative weights, got {value!r}")
    return weights


def _reduced_likelihood(table: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """P(value | category) times the evidence on the value, summed over the value: over the
    category. The two einsum calls of pgmpy's `DiscreteFactor.product` and `.marginalize`
    (the same values to the last bit, checked against pgmpy in the tests)."""
    product = np.einsum(table, [0, 1], weights, [1], [0, 1])
    return np.einsum(product, [0, 1], [0])


def _factor(variables: list[str], cardinality: list[int], values: np.ndarray
            ) -> DiscreteFactor:
    """A pgmpy factor (pgmpy imported on the first export only)."""
    from pgmpy.factors.discrete import DiscreteFactor

    return DiscreteFactor(variables, cardinality, values)
