"""Generate AVS-domain problems (text) of a given size: places, placeholders, rooms, labels.

Rooms are strung along a corridor-like chain of places; every room gets at least one place;
placeholders hang off random places and may lead into new rooms. Categories of some rooms are
known, the others have a distribution. All p-* values the domain may read are written.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

CATEGORIES = ("kitchen", "office", "corridor")
LABELS = ("cerealbox", "table", "cup", "stapler", "marker", "book", "shelf", "counter",
          "desk", "bottle", "laptop", "plant")
SUPPORTS = ("table", "shelf", "counter", "desk")


@dataclass(frozen=True)
class AvsSize:
    places: int = 20
    placeholders: int = 5
    rooms: int = 4
    labels: int = 8
    virtual_rooms: int = 2
    virtual_objects: int = 3

    @property
    def name(self) -> str:
        return f"avs-p{self.places}-h{self.placeholders}-r{self.rooms}-l{self.labels}"


def _dist(rng: random.Random, n: int) -> list[float]:
    weights = [rng.random() + 0.05 for _ in range(n)]
    total = sum(weights)
    return [round(w / total, 3) for w in weights]


def generate(size: AvsSize, seed: int = 0) -> str:
    """A problem for domains/avs/domain.pddl; the goal reports the first label."""
    rng = random.Random(seed)
    n_real = size.places - size.placeholders
    places = [f"place{i}" for i in range(n_real)]
    holders = [f"ph{i}" for i in range(size.placeholders)]
    rooms = [f"room{i}" for i in range(size.rooms)]
    vrooms = [f"new-room{i + 1}" for i in range(size.virtual_rooms)]
    vobjs = [f"new-object{i + 1}" for i in range(size.virtual_objects)]
    labels = list(LABELS[: max(2, size.labels)])
    if "table" not in labels:
        labels[1] = "table"
    room_of = {p: rooms[min(i * size.rooms // n_real, size.rooms - 1)]
               for i, p in enumerate(places)}
    init = [f"(at {places[0]})", f"(visited {places[0]})"]
    costs: dict[tuple[str, str], int] = {}

    def connect(a: str, b: str) -> None:
        d = rng.randint(2, 6)
        init.extend([f"(connected {a} {b})", f"(connected {b} {a})"])
        costs[(a, b)] = costs[(b, a)] = d

    for a, b in zip(places, places[1:], strict=False):
        connect(a, b)
    for _ in range(n_real // 4):
        a, b = rng.sample(places, 2)
        if (a, b) not in costs:
            connect(a, b)
    for p in places:
        init.append(f"(in-room {p} {room_of[p]})")
        if rng.random() < 0.5:
            init.append(f"(visited {p})")
    for h in holders:
        anchor = rng.choice(places)
        connect(anchor, h)
        init.append(f"(in-room {h} {room_of[anchor]})")
    values = _values(rng, size, rooms, vrooms, holders, labels, init)
    values += _find_on(values, labels, vobjs)
    values += [f"(= (move-cost {a} {b}) {d})" for (a, b), d in sorted(costs.items())]
    init += [f"(virtual {v})" for v in vrooms + vobjs]
    return _text(size, seed, places, holders, rooms, vrooms, vobjs, labels, init, values)


def _values(rng, size, rooms, vrooms, holders, labels, init) -> list[str]:
    values = []
    for i, r in enumerate(rooms):
        dist = [1.0 if c == "corridor" else 0.0 for c in CATEGORIES] if i == 0 else None
        if i == 0 or rng.random() < 0.4:
            cat = "corridor" if i == 0 else rng.choice(CATEGORIES[:2])
            init += [f"(has-category {r} {cat})", f"(defined-category {r})"]
            dist = [1.0 if c == cat else 0.0 for c in CATEGORIES]
        dist = dist or _dist(rng, len(CATEGORIES))
        values += [f"(= (p-room-category {r} {c}) {p})"
                   for c, p in zip(CATEGORIES, dist, strict=True)]
    for r in vrooms:
        values += [f"(= (p-room-category {r} {c}) 0)" for c in CATEGORIES]
    for h in holders:
        dist = [round(p * 0.8, 3) for p in _dist(rng, len(CATEGORIES))]
        values += [f"(= (p-placeholder-category {h} {c}) {p})"
                   for c, p in zip(CATEGORIES, dist, strict=True)]
    for label in labels:
        base = {c: round(rng.uniform(0.05, 0.9), 2) for c in CATEGORIES}
        for r in rooms + vrooms:
            values += [f"(= (p-obj-in {label} {r} {c}) {base[c]})" for c in CATEGORIES]
        for support in labels:
            for c in CATEGORIES:
                p = round(rng.uniform(0.1, 0.8), 2) if support in SUPPORTS and support != label \
                    else 0
                values.append(f"(= (p-obj-on {label} {support} {c}) {p})")
        for rel, cost in (("in", rng.randint(30, 120)), ("on", rng.randint(8, 20))):
            values.append(f"(= (search-cost {label} {rel}) {cost})")
            values.append(f"(= (p-detect {label} {rel}) {round(rng.uniform(0.5, 0.9), 2)})")
    return values


def _find_on(values: list[str], labels: list[str], vobjs: list[str]) -> list[str]:
    """`p-find-on L S`: nothing has looked at any support yet, so each is L's detection rate
    on a support (no random draw: the other values stay what they were for a seed)."""
    rate = {}
    for v in values:
        if v.startswith("(= (p-detect ") and " on) " in v:
            label = v.split()[2]
            rate[label] = v.rsplit(" ", 1)[1].rstrip(")")
    return [f"(= (p-find-on {label} {o}) {rate[label]})" for label in labels for o in vobjs]


def _text(size, seed, places, holders, rooms, vrooms, vobjs, labels, init, values) -> str:
    objects = [
        " ".join(places) + " - place", " ".join(holders) + " - placeholder",
        " ".join(rooms + vrooms) + " - room", " ".join(vobjs) + " - visualobject",
        " ".join(labels) + " - label", " ".join(CATEGORIES) + " - category",
    ]
    body = "\n    ".join(init + ["(= (total-cost) 0)"] + values)
    return (
        f";; generated by bench/avs_generator.py, seed {seed}\n"
        f"(define (problem {size.name}-s{seed})\n  (:domain avs)\n"
        f"  (:objects\n    " + "\n    ".join(objects) + ")\n"
        f"  (:init\n    {body})\n"
        f"  (:goal (reported {labels[0]}))\n  (:metric minimize (total-cost)))\n"
    )
