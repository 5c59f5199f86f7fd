"""Object existence as Poisson processes (eq. 1-2 of the active visual search paper by
Göbelbecker et al.) and the evidence objects give.

Given a room's category c, the number of `label` objects at a location L is Poisson(lambda_{L,c});
locations are independent, so lambdas add over a location and its sub-locations. A search that
covers a fraction `coverage` of L with detector reliability `p_detect` finds each object with
q = coverage * p_detect; after failed searches the undetected count is Poisson(lambda * r) with
r = prod(1 - q_i), and the failures have likelihood exp(-lambda * (1 - r)) (Poisson thinning).

The lambdas are hand-set for buildings in general; one building may hold far fewer staplers
than they say, or none. With a `rate_shape` a in the knowledge, a label's counts in this
building are Poisson(s * lambda) with one multiplier s ~ Gamma(a, a) (mean 1) shared by all
its locations. Finding n of them after looks that would have seen an expected E (the looked-at
part of every location's lambda, over the category belief) leaves s ~ Gamma(a + n, a + E),
and the count in an unseen expected mass m is negative binomial:
P(n >= 1) = 1 - (beta / (beta + m))^alpha (`RatePosterior`). So six offices searched in vain
make a stapler in the seventh less likely, which independent counts per room never do (the
gamma-Poisson mixture; the count models of Göbelbecker et al., "A Planning Approach to Active
Visual Search in Large Environments", with the rate itself uncertain).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np
from scipy import special

from conceptual_map.conceptual.errors import ConceptualError
from conceptual_map.knowledge import RELATIONS, Knowledge


@dataclass(frozen=True)
class RelatedSpace:
    """The space `relation` ("in"/"on") a known object, e.g. on object1 (a table)."""

    relation: str
    object_id: str


Location = str | RelatedSpace
"""A room id, or a related space of a known object."""


@dataclass(frozen=True)
class ObjectRecord:
    """A detected object; `support` is the object it is on/in, if any."""

    object_id: str
    label: str
    room: str
    relation: str | None = None
    support: str | None = None

    @property
    def location(self) -> Location:
        if self.support is None or self.relation is None:
            return self.room
        return RelatedSpace(self.relation, self.support)


def p_at_least_one(lam: np.ndarray | float) -> np.ndarray:
    """P(n >= 1) = 1 - exp(-lambda)."""
    return -np.expm1(-np.asarray(lam, dtype=float))


def p_at_least(k: int, lam: np.ndarray | float) -> np.ndarray:
    """P(n >= k) for n ~ Poisson(lambda): `scipy.stats.poisson.sf(k - 1, lambda)`, computed as
    it does (the regularised gamma function `pdtrc`, clipped to [0, 1]; 1 for k <= 0; NaN for
    a lambda that is negative or NaN) without importing scipy.stats, which alone took ~0.35 s
    of an episode's start."""
    lam = np.asarray(lam, dtype=float)
    valid = lam >= 0
    if k <= 0:
        return np.where(valid, 1.0, np.nan)
    return np.where(valid, np.clip(special.pdtrc(np.floor(k - 1), lam), 0.0, 1.0), np.nan)


@dataclass(frozen=True)
class RatePosterior:
    """What one building's evidence says of a label's rate multiplier: Gamma(alpha, beta)."""

    alpha: float
    beta: float

    @classmethod
    def after(cls, shape: float, found: int, exposure: float) -> RatePosterior:
        """Gamma(a, a) prior; `found` objects seen where looks had expected `exposure`."""
        return cls(shape + found, shape + max(0.0, exposure))

    @property
    def mean(self) -> float:
        return self.alpha / self.beta

    def p_any(self, lam: np.ndarray | float) -> np.ndarray:
        """P(n >= 1) for n ~ Poisson(s * lam), s ~ this posterior (negative binomial)."""
        lam = np.asarray(lam, dtype=float)
        return -np.expm1(-self.alpha * np.log1p(lam / self.beta))

    def p_none(self, lam: np.ndarray | float) -> np.ndarray:
        return 1.0 - self.p_any(lam)

    def mass(self, p: np.ndarray | float) -> np.ndarray:
        """The expected count whose `p_any` is `p` (its inverse): masses add, p's do not."""
        p = np.clip(np.asarray(p, dtype=float), 0.0, 1.0 - 1e-12)
        return self.beta * np.expm1(-np.log1p(-p) / self.alpha)


def failed_search_likelihood(lam: np.ndarray | float, remaining: float) -> np.ndarray:
    """P(nothing detected | lambda) after searches leaving a fraction `remaining` unseen."""
    return np.exp(-np.asarray(lam, dtype=float) * (1.0 - remaining))


class ObjectLedger:
    """Detected objects and failed searches, and the category likelihoods they imply."""

    def __init__(self, knowledge: Knowledge) -> None:
        self.knowledge = knowledge
        self.objects: dict[str, ObjectRecord] = {}
        self._counts: dict[Location, Counter[str]] = {}
        self._remaining: dict[tuple[Location, str], float] = {}
        # share of `label` objects at a location that frames taken in passing would have
        # seen (fraction of the location in view x detection probability); set, not
        # multiplied, since those frames overlap: the latest share replaces the last
        self._glimpsed: dict[tuple[Location, str], float] = {}

    def add(
        self,
        label: str,
        room: str,
        relation: str | None = None,
        support: str | None = None,
        object_id: str | None = None,
    ) -> ObjectRecord:
        """Record a detected object (a fresh id `object<N>` unless one is given)."""
        self.require_label(label)
        if support is not None:
            self._check_support(room, relation, support)
        object_id = object_id or self._fresh_id()
        if object_id in self.objects:
            raise ConceptualError(f"object id {object_id!r} is already used")
        record = ObjectRecord(object_id, label, room, relation, support)
        self.objects[object_id] = record
        self._counts.setdefault(record.location, Counter())[label] += 1
        return record

    def remove(self, object_id: str) -> ObjectRecord:
        """Take back a detected object (it proved a false detection); objects on it first."""
        record = self.objects.get(object_id)
        if record is None:
            raise ConceptualError(f"unknown object {object_id!r}")
        held = [o for o, r in self.objects.items() if r.support == object_id]
        if held:
            raise ConceptualError(f"object {object_id!r} still holds {', '.join(held)}")
        del self.objects[object_id]
        counts = self._counts.get(record.location)
        if counts is not None:
            counts[record.label] -= 1
            if counts[record.label] <= 0:
                del counts[record.label]
        return record

    def _check_support(self, room: str, relation: str | None, support: str) -> None:
        if relation not in RELATIONS:
            raise ConceptualError(f"relation must be one of {RELATIONS}, got {relation!r}")
        holder = self.objects.get(support)
        if holder is None:
            raise ConceptualError(f"unknown support object {support!r}")
        if holder.room != room:
            raise ConceptualError(f"support {support!r} is in room {holder.room!r}, not {room!r}")

    def _fresh_id(self) -> str:
        n = len(self.objects) + 1
        while f"object{n}" in self.objects:
            n += 1
        return f"object{n}"

    def require_label(self, label: str) -> None:
        if label not in self.knowledge.object_lambda:
            raise ConceptualError(f"unknown object label {label!r} (not in the knowledge)")

    def room_of(self, location: Location) -> str:
        """The room whose category governs `location`."""
        if isinstance(location, RelatedSpace):
            if location.relation not in RELATIONS:
                raise ConceptualError(f"relation must be one of {RELATIONS}: {location!r}")
            holder = self.objects.get(location.object_id)
            if holder is None:
                raise ConceptualError(f"unknown object {location.object_id!r} in {location!r}")
            return holder.room
        return location

    def record_search(
        self, label: str, location: Location, coverage: float, p_detect: float
    ) -> None:
        """A search of `location` for `label` looked through `coverage` of it.

        Whether or not it found one, the `label` objects it did not see are Poisson with the
        lambda thinned by (1 - coverage * p_detect): after a search that found a desk, a
        second desk is only as likely as the unlooked part of the room allows.
        """
        self.require_label(label)
        self.room_of(location)
        for name, value in (("coverage", coverage), ("p_detect", p_detect)):
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ConceptualError(f"{name} must be a number in [0, 1], got {value!r}")
            if not 0.0 <= value <= 1.0:
                raise ConceptualError(f"{name} must be in [0, 1], got {value!r}")
        key = (location, label)
        self._remaining[key] = self._remaining.get(key, 1.0) * (1.0 - coverage * p_detect)

    def record_glimpses(self, label: str, location: Location, share: float) -> None:
        """Frames taken in passing (not a search) have looked at part of `location` and not
        seen `label`: `share` = the part in view x the detection probability, in [0, 1]."""
        self.require_label(label)
        self.room_of(location)
        if isinstance(share, bool) or not isinstance(share, int | float) \
                or not 0.0 <= share <= 1.0:
            raise ConceptualError(f"share must be a number in [0, 1], got {share!r}")
        self._glimpsed[(location, label)] = float(share)

    def count(self, location: Location, label: str) -> int:
        return self._counts.get(location, Counter())[label]

    def remaining(self, location: Location, label: str) -> float:
        """Fraction of `label` objects at `location` that searches so far would have missed
        (and the frames taken in passing, as one more independent look)."""
        key = (location, label)
        return self._remaining.get(key, 1.0) * (1.0 - self._glimpsed.get(key, 0.0))

    def unexplained_lambda(self, label: str, room: str) -> np.ndarray:
        """Per category, the expected count of `label` in `room` that no known object's space
        holds and no look so far has ruled out.

        The room's own lambda, thinned by the looks for `label` there, plus, for every
        support the knowledge puts `label` on or in, the supports of that label not found
        yet (their prior count thinned by the looks for the support label there: Poisson
        thinning, so the undiscovered count does not depend on how many were found) times
        the per-support lambda. Supports already found hold their share in their own
        related spaces. A support label nothing has looked for yet is thinned by the looks
        for `label` instead (the old rule for every support).
        """
        self.require_label(label)
        knowledge = self.knowledge
        total = knowledge.room_lambda(label) * self.remaining(room, label)
        for (lab, _relation, support), lam in knowledge.relation_lambda.items():
            if lab != label:
                continue
            looked = self._looked_for(room, support)
            unseen = self.remaining(room, support if looked else label)
            total = total + knowledge.room_lambda(support) * unseen * lam
        return total

    def searched_lambda(self, label: str, room: str) -> np.ndarray:
        """Per category, the expected count of `label` in `room` that the looks for it there
        would have seen: the exposure of the building's rate to this room's evidence. It is
        the part of the prior count that `unsearched_lambda` thins by looks for `label`
        itself: the room, supports not found yet while nothing has looked for their label
        (once something has, their unseen count is thinned by those looks, which test how
        many supports there are, not how many `label`s they hold), and the spaces of known
        supports."""
        self.require_label(label)
        knowledge = self.knowledge
        seen = 1.0 - self.remaining(room, label)
        total = knowledge.room_lambda(label) * seen
        for (lab, _relation, support), lam in knowledge.relation_lambda.items():
            if lab == label and not self._looked_for(room, support):
                total = total + knowledge.room_lambda(support) * seen * lam
        for space in self.sublocations(room, label):
            total = total + self.location_lambda(label, space) * (
                1.0 - self.remaining(space, label))
        return total

    def _looked_for(self, room: str, label: str) -> bool:
        return (room, label) in self._remaining or (room, label) in self._glimpsed

    def looked_rooms(self, label: str) -> set[str]:
        """Rooms where some look for `label` was recorded (searches, glimpses)."""
        rooms = set()
        for loc, lab in (*self._remaining, *self._glimpsed):
            if lab != label:
                continue
            if isinstance(loc, RelatedSpace):
                holder = self.objects.get(loc.object_id)
                if holder is not None:  # a support taken back as a false detection: gone
                    rooms.add(holder.room)
            else:
                rooms.add(loc)
        return rooms

    def found(self, label: str) -> int:
        return sum(1 for r in self.objects.values() if r.label == label)

    def unsearched_lambda(self, label: str, room: str) -> np.ndarray:
        """Per category, the expected count of `label` in `room` that no look has ruled out:
        `unexplained_lambda` plus the related spaces of the room's known objects, each
        thinned by the looks there."""
        total = self.unexplained_lambda(label, room)
        for space in self.sublocations(room, label):
            total = total + self.location_lambda(label, space) * self.remaining(space, label)
        return total

    def fresh_room_lambda(self, label: str) -> np.ndarray:
        """Per category, the expected count of `label` in a room nobody has looked at: its
        floor and walls plus, for each support the knowledge lists, that support's count
        times what one holds."""
        self.require_label(label)
        knowledge = self.knowledge
        total = knowledge.room_lambda(label)
        for (lab, _relation, support), lam in knowledge.relation_lambda.items():
            if lab == label:
                total = total + knowledge.room_lambda(support) * lam
        return total

    def location_lambda(self, label: str, location: Location) -> np.ndarray:
        """Prior expected count of `label` at `location`, per category."""
        self.require_label(label)
        if isinstance(location, RelatedSpace):
            self.room_of(location)
            support = self.objects[location.object_id].label
            return self.knowledge.relation_lambda_of(label, location.relation, support)
        return self.knowledge.room_lambda(label)

    def sublocations(self, room: str, label: str) -> list[RelatedSpace]:
        """Related spaces of objects in `room` where the knowledge expects `label` (in/on).

        Only (label, relation, support) entries the knowledge lists count, so default lambdas
        of unlisted pairs (a cereal box in a cup) do not pile up over many objects.
        """
        listed = self.knowledge.relation_lambda
        return [
            RelatedSpace(relation, record.object_id)
            for record in self.objects.values()
            if record.room == room
            for relation in RELATIONS
            if (label, relation, record.label) in listed
        ]

    def room_likelihood(self, room: str) -> np.ndarray:
        """P(all object evidence in `room` | category): counts seen and failed searches.

        A location where k >= 1 objects of a label were seen contributes P(n >= k); searches
        there are then ignored (they succeeded). Otherwise failed searches contribute
        exp(-lambda (1 - r)).
        """
        likelihood = np.ones(len(self.knowledge.categories))
        for location, label in self._evidence_keys():
            if self.room_of(location) != room:
                continue
            lam = self.location_lambda(label, location)
            seen = self.count(location, label)
            if seen:
                likelihood *= p_at_least(seen, lam)
            else:
                likelihood *= failed_search_likelihood(lam, self.remaining(location, label))
        return likelihood

    def _evidence_keys(self) -> set[tuple[Location, str]]:
        keys = {(loc, label) for loc, counts in self._counts.items() for label in counts}
        return keys | set(self._remaining) | set(self._glimpsed)

    def forget_room(self, room: str) -> None:
        """Drop room-level search records of a deleted room (it holds no objects)."""
        for records in (self._remaining, self._glimpsed):
            for key in [k for k in records if k[0] == room]:
                del records[key]
        self._counts.pop(room, None)

    def move_object(self, object_id: str, room: str) -> str:
        """A detected object turned out to stand in `room` (the map parted the space it was
        credited to): it moves there with what stands on or in it, and its count with it.
        Returns the room it was in."""
        record = self.objects.get(object_id)
        if record is None:
            raise ConceptualError(f"unknown object {object_id!r}")
        if record.support is not None:
            raise ConceptualError(f"object {object_id!r} is {record.relation} "
                                  f"{record.support!r}: it moves with it")
        old = record.room
        if old == room:
            return old
        moving = [object_id]
        for oid in moving:  # what stands on it, and on that, ...
            moving += [o for o, r in self.objects.items() if r.support == oid and o not in moving]
        for oid in moving:
            r = self.objects[oid]
            self.objects[oid] = ObjectRecord(oid, r.label, room, r.relation, r.support)
        counts = self._counts.get(old)
        if counts is not None:
            counts[record.label] -= 1
            if counts[record.label] <= 0:
                del counts[record.label]
        self._counts.setdefault(room, Counter())[record.label] += 1
        return old

    def move_room(self, gone: str, keep: str) -> None:
        """Objects and room-level searches of `gone` now belong to `keep` (rooms merged).

        Searched fractions cannot be combined without areas, so the merged room keeps the larger
        unseen fraction: it never claims more coverage than a search achieved.
        """
        for object_id, record in list(self.objects.items()):
            if record.room == gone:
                self.objects[object_id] = ObjectRecord(
                    object_id, record.label, keep, record.relation, record.support
                )
        moved = self._counts.pop(gone, Counter())
        self._counts.setdefault(keep, Counter()).update(moved)
        for (location, label), fraction in list(self._remaining.items()):
            if location == gone:
                del self._remaining[(location, label)]
                self._remaining[(keep, label)] = max(fraction,
                                                     self._remaining.get((keep, label), 1.0))
        # glimpses are shares of a room's area: the merged room's is not known until the
        # next frame gives it, so keep the smaller (a room never glimpsed counts as 0)
        for label in {k[1] for k in self._glimpsed if k[0] in (gone, keep)}:
            share = min(self._glimpsed.pop((gone, label), 0.0),
                        self._glimpsed.pop((keep, label), 0.0))
            if share > 0.0:
                self._glimpsed[(keep, label)] = share
