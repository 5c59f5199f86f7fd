"""Priors learned from experience: an SQLite store of what finished episodes saw, and the
knowledge it makes of the hand-set file.

The hand-set knowledge (`default.yaml`) says how many of each label a room of each category
holds (`object_lambda`), how many one support holds (`relation_lambda`), how common each room
category is (`prior`) and which categories neighbour which (`connectivity`). Episodes that
searched buildings have evidence on all four; the store keeps it as counts, per *scope*:
`all` (every building) and `building:<id>` (one building), and `knowledge_for` turns the
counts into posterior means:

- **Rates** (object in a room of category c; object `on`/`in` one support of category c's
  rooms): a Poisson count with rate lambda per unit of exposure, the unit being one room (or
  one support instance) looked through completely with a perfect detector. An episode adds
  the objects it found, n, and its exposure E, the rooms' worth its looks covered (each
  look's share of the room times the detector's hit rate: `1 - remaining` in the object
  ledger). The conjugate prior on lambda is a Gamma centred on the file's rate lambda0 and
  worth `PRIOR_EXPOSURE` (b0) units of exposure, so the posterior mean is
  (b0 lambda0 + n) / (b0 + E) (`learned.posterior_mean`, where the choice is explained);
  one building's rate is the same update again with the all-buildings posterior as its
  prior mean and the knowledge's `rate_shape` as the Gamma's shape (how much buildings
  differ from buildings in general, the same number the episode's own rate multiplier
  uses), fed with that building's counts only; the all-buildings level then takes the other
  buildings' counts (all less this one), so no episode counts twice. A relation the file
  does not list is added once something was found on such a support.
- **Room categories**: a Dirichlet with concentration `CATEGORY_STRENGTH` x the file's prior
  and the counts of rooms seen per category: posterior mean (alpha pi_c + n_c) / (alpha + N);
  then one building's counts on top of that with `BUILDING_CATEGORY_STRENGTH`.
- **Neighbours** (`connectivity`, a symmetric potential phi): rooms joined by a door are a
  draw of an unordered pair of categories, P0(a, b) proportional to pi_a pi_b phi(a, b); a
  Dirichlet with concentration `NEIGHBOUR_STRENGTH` x P0 and the pair counts gives
  P(a, b) = (alpha P0 + n_ab) / (alpha + N), and phi is scaled by P / P0 (unchanged without
  counts; the rest of the chain graph is taken as it was: an approximation).
- **QSR descriptions** (the QSR strategy's learned counts, `conceptual_map/qsr/learning.py`):
  each learned observation adds one to its description's mixture weight (`qsr_for`, from the
  all-buildings scope, which already holds every building's).

No state is kept in the process: a store is an object made from a file path and passed to
whoever reads or writes it; two episodes on the same file contents get the same knowledge.
"""

from __future__ import annotations

import json
import re
import sqlite3
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from conceptual_map.errors import ExperienceError
from conceptual_map.knowledge.learned import (
    BUILDING_CATEGORY_STRENGTH,
    CATEGORY_STRENGTH,
    PRIOR_EXPOSURE,
    Counts,
    posterior_knowledge,
    posterior_mean,
    posterior_rate,
    rate_of,
)
from conceptual_map.knowledge.model import Knowledge
from conceptual_map.qsr.model import QsrDescription, QsrKnowledge, QsrStep

SCHEMA_VERSION = 1
STORE_KIND = "avs-experience"
ALL = "all"
BUILDING_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")

BUSY_TIMEOUT_S = 60.0
"""How long a write waits for another process's transaction on the same file (SQLite's busy
timeout): episodes running side by side in a campaign add to one store, each in one short
transaction."""

@dataclass(frozen=True)
class Evidence:
    """What one finished episode saw, as counts (built from the robot's mind only,
    `avs_planner/episode/experience.py`).

    `rooms`: (label, category) -> (found, exposure in rooms); `supports`: (label, relation,
    support label, category) -> (found, exposure in support instances); `categories`:
    category -> rooms seen; `neighbours`: (category, category), sorted -> door links seen;
    `qsr`: (target, chain as `qsr_chain_key`) -> observations learned."""

    rooms: Mapping[tuple[str, str], tuple[float, float]] = field(default_factory=dict)
    supports: Mapping[tuple[str, str, str, str], tuple[float, float]] = field(
        default_factory=dict)
    categories: Mapping[str, float] = field(default_factory=dict)
    neighbours: Mapping[tuple[str, str], float] = field(default_factory=dict)
    qsr: Mapping[tuple[str, str], float] = field(default_factory=dict)

    @property
    def empty(self) -> bool:
        return not (self.rooms or self.supports or self.categories or self.neighbours
                    or self.qsr)


def qsr_chain_key(chain: Iterable[QsrStep]) -> str:
    """A description's chain as text (JSON: [[relations, of], ...]), its key in the store."""
    return json.dumps([[list(step.relations), step.of] for step in chain])


def _chain(key: str) -> tuple[QsrStep, ...]:
    return tuple(QsrStep(tuple(relations), of) for relations, of in json.loads(key))


def building_scope(building: str) -> str:
    """The scope of one building; ExperienceError for an id that is not
    `[A-Za-z0-9][A-Za-z0-9_.-]{0,63}`."""
    if not isinstance(building, str) or not BUILDING_ID.match(building):
        raise ExperienceError(f"building id {building!r} must match {BUILDING_ID.pattern}")
    return f"building:{building}"


_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS episodes (scope TEXT PRIMARY KEY, count INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS rates (
    scope TEXT NOT NULL, kind TEXT NOT NULL, label TEXT NOT NULL, relation TEXT NOT NULL,
    support TEXT NOT NULL, category TEXT NOT NULL, found REAL NOT NULL, exposure REAL NOT NULL,
    PRIMARY KEY (scope, kind, label, relation, support, category));
CREATE TABLE IF NOT EXISTS categories (
    scope TEXT NOT NULL, category TEXT NOT NULL, count REAL NOT NULL,
    PRIMARY KEY (scope, category));
CREATE TABLE IF NOT EXISTS neighbours (
    scope TEXT NOT NULL, a TEXT NOT NULL, b TEXT NOT NULL, count REAL NOT NULL,
    PRIMARY KEY (scope, a, b));
CREATE TABLE IF NOT EXISTS qsr (
    scope TEXT NOT NULL, target TEXT NOT NULL, chain TEXT NOT NULL, count REAL NOT NULL,
    PRIMARY KEY (scope, target, chain));
"""
_TABLES = ("episodes", "rates", "categories", "neighbours", "qsr")


class ExperienceStore:
    """Counts of what episodes found, per scope, in one SQLite file (see the module doc).

    `ExperienceStore(path)` opens the file, making a new store when it does not exist (or is
    empty) and `create` is true; ExperienceError for a file that is not such a store. With
    `readonly`, the file must exist and is opened read-only (SQLite's `mode=ro`): `update`
    and `reset` fail, and the file is left as it was. Use it as a context manager, or
    `close` it."""

    def __init__(self, path: str | Path, create: bool = True, readonly: bool = False) -> None:
        self.path = Path(path)
        self.readonly = readonly
        exists = self.path.is_file() and self.path.stat().st_size > 0
        if not exists and (readonly or not create):
            raise ExperienceError(f"{self.path}: no experience store there")
        if self.path.exists() and not self.path.is_file():
            raise ExperienceError(f"{self.path}: not a file")
        try:
            if readonly:
                self._db = sqlite3.connect(f"{self.path.resolve().as_uri()}?mode=ro",
                                           uri=True, timeout=BUSY_TIMEOUT_S)
            else:
                self._db = sqlite3.connect(self.path, timeout=BUSY_TIMEOUT_S)
        except sqlite3.Error as exc:
            raise ExperienceError(f"{self.path}: cannot open: {exc}") from None
        try:
            if exists:
                self._check()
            else:
                with self._db:
                    self._db.executescript(_SCHEMA)
                    self._db.executemany("INSERT INTO meta VALUES (?, ?)",
                                         [("kind", STORE_KIND),
                                          ("schema_version", str(SCHEMA_VERSION))])
        except sqlite3.Error as exc:
            self._db.close()
            raise ExperienceError(f"{self.path}: not an experience store ({exc})") from None
        except ExperienceError:
            self._db.close()
            raise

    def _check(self) -> None:
        tables = {row[0] for row in self._db.execute(
            "SELECT name FROM sqlite_master WHERE type = 'table'")}
        if "meta" not in tables:
            raise ExperienceError(f"{self.path}: not an experience store (an SQLite file "
                                  f"without its meta table)")
        meta = dict(self._db.execute("SELECT key, value FROM meta").fetchall())
        if meta.get("kind") != STORE_KIND:
            raise ExperienceError(f"{self.path}: not an experience store (kind "
                                  f"{meta.get('kind')!r})")
        version = meta.get("schema_version")
        if version != str(SCHEMA_VERSION):
            raise ExperienceError(f"{self.path}: experience store of schema version {version},"
                                  f" this version of avs reads {SCHEMA_VERSION}")
        missing = sorted(set(_TABLES) - tables)
        if missing:
            raise ExperienceError(f"{self.path}: damaged experience store (no table(s) "
                                  f"{', '.join(missing)})")

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> ExperienceStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def _read(self) -> Iterator[sqlite3.Connection]:
        try:
            yield self._db
        except sqlite3.Error as exc:
            raise ExperienceError(f"{self.path}: cannot read the experience store: "
                                  f"{exc}") from None

    # -- writing ---------------------------------------------------------------------------

    def update(self, building: str | None, evidence: Evidence) -> None:
        """Add one episode's evidence to the all-buildings scope and, given a building, to
        its scope: one transaction (both or neither)."""
        if self.readonly:
            raise ExperienceError(f"{self.path}: opened read-only; nothing is added")
        scopes = [ALL] + ([building_scope(building)] if building is not None else [])
        rows_rates = [(kind, *key, found, exposure)
                      for kind, table in (("room", evidence.rooms), ("support", evidence.supports))
                      for key, (found, exposure) in _rate_rows(kind, table)]
        try:
            with self._db:
                for scope in scopes:
                    self._db.execute(
                        "INSERT INTO episodes VALUES (?, 1) ON CONFLICT (scope) "
                        "DO UPDATE SET count = count + 1", (scope,))
                    self._db.executemany(
                        "INSERT INTO rates VALUES (?, ?, ?, ?, ?, ?, ?, ?) "
                        "ON CONFLICT (scope, kind, label, relation, support, category) DO UPDATE "
                        "SET found = found + excluded.found, "
                        "exposure = exposure + excluded.exposure",
                        [(scope, *row) for row in rows_rates])
                    self._db.executemany(
                        "INSERT INTO categories VALUES (?, ?, ?) ON CONFLICT (scope, category) "
                        "DO UPDATE SET count = count + excluded.count",
                        [(scope, c, float(n)) for c, n in evidence.categories.items()])
                    self._db.executemany(
                        "INSERT INTO neighbours VALUES (?, ?, ?, ?) ON CONFLICT (scope, a, b) "
                        "DO UPDATE SET count = count + excluded.count",
                        [(scope, *sorted(pair), float(n))
                         for pair, n in evidence.neighbours.items()])
                    self._db.executemany(
                        "INSERT INTO qsr VALUES (?, ?, ?, ?) ON CONFLICT (scope, target, chain) "
                        "DO UPDATE SET count = count + excluded.count",
                        [(scope, target, chain, float(n))
                         for (target, chain), n in evidence.qsr.items()])
        except sqlite3.Error as exc:
            raise ExperienceError(f"{self.path}: cannot write the experience store: "
                                  f"{exc}") from None

    def reset(self, scope: str | None = None) -> int:
        """Forget the counts of `scope` (`all`, or `building:<id>`), or of every scope when
        None; returns the rows removed. Resetting one building leaves what it taught in the
        all-buildings scope (those counts are not kept per building)."""
        if scope is not None and scope != ALL:
            building_scope(scope.removeprefix("building:"))
        removed = 0
        try:
            with self._db:
                for table in _TABLES:
                    if scope is None:
                        removed += self._db.execute(f"DELETE FROM {table}").rowcount
                    else:
                        removed += self._db.execute(f"DELETE FROM {table} WHERE scope = ?",
                                                    (scope,)).rowcount
        except sqlite3.Error as exc:
            raise ExperienceError(f"{self.path}: cannot write the experience store: "
                                  f"{exc}") from None
        return removed

    # -- reading ---------------------------------------------------------------------------

    def scopes(self) -> list[str]:
        """Scopes with any counts, `all` first."""
        with self._read() as db:
            found = {row[0] for table in _TABLES
                     for row in db.execute(f"SELECT DISTINCT scope FROM {table}")}
        return sorted(found, key=lambda s: (s != ALL, s))

    def _rates(self, scope: str, kind: str) -> Counts:
        with self._read() as db:
            rows = db.execute("SELECT label, relation, support, category, found, exposure "
                              "FROM rates WHERE scope = ? AND kind = ?", (scope, kind))
            return {(lab, cat) if kind == "room" else (lab, rel, sup, cat): (found, exposure)
                    for lab, rel, sup, cat, found, exposure in rows}

    def _counts(self, table: str, scope: str) -> dict[Any, float]:
        with self._read() as db:
            if table == "categories":
                rows = db.execute("SELECT category, count FROM categories WHERE scope = ?",
                                  (scope,))
                return {c: n for c, n in rows}
            if table == "neighbours":
                rows = db.execute("SELECT a, b, count FROM neighbours WHERE scope = ?", (scope,))
                return {(a, b): n for a, b, n in rows}
            rows = db.execute("SELECT target, chain, count FROM qsr WHERE scope = ?", (scope,))
            return {(t, c): n for t, c, n in rows}

    def _episodes(self, scope: str) -> int:
        with self._read() as db:
            row = db.execute("SELECT count FROM episodes WHERE scope = ?", (scope,)).fetchone()
        return int(row[0]) if row else 0

    def knowledge_for(self, base: Knowledge, building: str | None = None) -> Knowledge:
        """`base` with posterior-mean rates, category prior and connectivity: the
        all-buildings counts on the file, then `building`'s own on top (module doc)."""
        scope = building_scope(building) if building is not None else None
        levels = [(_less(self._rates(ALL, kind), self._rates(scope, kind)) if scope else
                   self._rates(ALL, kind)) for kind in ("room", "support")]
        rooms, supports = levels
        categories = self._counts("categories", ALL)
        neighbours = self._counts("neighbours", ALL)
        if scope is not None:
            categories = _less(categories, self._counts("categories", scope))
            neighbours = _less(neighbours, self._counts("neighbours", scope))
        knowledge = posterior_knowledge(base, rooms, supports, categories, neighbours,
                                        posterior_mean, CATEGORY_STRENGTH)
        if scope is not None:
            shape = base.rate_shape if base.rate_shape is not None else PRIOR_EXPOSURE

            def building_rate(prior: float, found: float, exposure: float) -> float:
                return posterior_rate(prior, shape, found, exposure)

            knowledge = posterior_knowledge(knowledge, self._rates(scope, "room"),
                                            self._rates(scope, "support"),
                                            self._counts("categories", scope),
                                            self._counts("neighbours", scope), building_rate,
                                            BUILDING_CATEGORY_STRENGTH)
        name = f"{base.source} + experience {self.path.name} ({scope or ALL})"
        return replace(knowledge, source=name, _category_index={})

    def qsr_for(self, base: QsrKnowledge) -> QsrKnowledge:
        """`base` with the learned QSR observations of the all-buildings scope added to its
        descriptions' counts (new descriptions appended); entries naming relations or
        landmarks `base` does not know are left out."""
        descriptions = list(base.descriptions)
        index = {d.key: i for i, d in enumerate(descriptions)}
        for (target, chain_key), count in sorted(self._counts("qsr", ALL).items()):
            chain = _chain(chain_key)
            if not all(set(s.relations) <= set(base.relations) and s.of in base.fronts
                       for s in chain):
                continue
            key = (target, chain)
            if key in index:
                old = descriptions[index[key]]
                descriptions[index[key]] = QsrDescription(target, chain, old.count + count)
            else:
                index[key] = len(descriptions)
                descriptions.append(QsrDescription(target, chain, count))
        return base.with_descriptions(tuple(descriptions))

    def export(self) -> dict[str, Any]:
        """Every count, as plain data: {schema_version, scopes: {scope: {...}}}."""
        scopes: dict[str, Any] = {}
        for scope in self.scopes():
            scopes[scope] = {
                "episodes": self._episodes(scope),
                "rooms": [{"label": lab, "category": cat, "found": n, "exposure": e}
                          for (lab, cat), (n, e) in sorted(self._rates(scope, "room").items())],
                "supports": [{"label": lab, "relation": rel, "support": sup, "category": cat,
                              "found": n, "exposure": e}
                             for (lab, rel, sup, cat), (n, e)
                             in sorted(self._rates(scope, "support").items())],
                "categories": dict(sorted(self._counts("categories", scope).items())),
                "neighbours": [{"categories": [a, b], "count": n} for (a, b), n
                               in sorted(self._counts("neighbours", scope).items())],
                "qsr": [{"target": t, "chain": json.loads(c), "count": n}
                        for (t, c), n in sorted(self._counts("qsr", scope).items())],
            }
        return {"store": self.path.name, "schema_version": SCHEMA_VERSION, "scopes": scopes}

    def show(self, base: Knowledge, building: str | None = None) -> dict[str, Any]:
        """What the store changes in `base` for `building` (or all buildings): per rate it
        has counts for, the file's value, the learned one and the counts, per category the
        prior both ways, and the episodes per scope; the counts shown are the scope's
        (the building's, when one is given)."""
        learned = self.knowledge_for(base, building)
        if self.readonly:
            raise ExperienceError(f"{self.path}: opened read-only; nothing is added")
        scopes = [ALL] + ([building_scope(building)] if building is not None else [])
        rates = []
        for kind in ("room", "support"):
            keys = sorted({k for s in scopes for k in self._rates(s, kind)})
            for key in keys:
                n, e = self._rates(scopes[-1], kind).get(key, (0.0, 0.0))
                before, after = rate_of(base, key), rate_of(learned, key)
                if before is None and after is not None and len(key) == 4:
                    before = float(base.default_relation_lambda)  # a relation learned
                if before is None or after is None:
                    continue
                entry = ({"label": key[0], "category": key[1]} if kind == "room" else
                         {"label": key[0], "relation": key[1], "support": key[2],
                          "category": key[3]})
                rates.append({**entry, "file": round(before, 4), "learned": round(after, 4),
                              "found": n, "exposure": round(e, 3)})
        categories = {c: {"file": round(float(base.prior[i]), 4),
                          "learned": round(float(learned.prior[i]), 4)}
                      for i, c in enumerate(base.categories)}
        return {"store": self.path.name, "scope": scopes[-1],
                "episodes": {s: self._episodes(s) for s in self.scopes()},
                "rates": rates, "categories": categories,
                "qsr_observations": sum(self._counts("qsr", ALL).values())}


def _rate_rows(kind: str, table: Mapping[Any, tuple[float, float]]
               ) -> Iterator[tuple[tuple[str, str, str, str], tuple[float, float]]]:
    for key, (found, exposure) in sorted(table.items()):
        if kind == "room":
            label, category = key
            yield (label, "", "", category), (float(found), float(exposure))
        else:
            yield tuple(key), (float(found), float(exposure))


def _less(total: Mapping[Any, Any], part: Mapping[Any, Any]) -> dict[Any, Any]:
    """`total` less `part`, key by key, never below 0 (a scope reset on its own)."""
    out = {}
    for key, value in total.items():
        minus = part.get(key)
        if minus is None:
            out[key] = value
        elif isinstance(value, tuple):
            out[key] = tuple(max(0.0, v - m) for v, m in zip(value, minus, strict=True))
        else:
            out[key] = max(0.0, value - minus)
    return out


@dataclass
class ExperienceSession:
    """One episode's use of a store: what its strategies read from it, and the QSR
    observations they learned, kept here until the episode ends well and the harness adds
    them, with the rest of the episode's evidence, in one update."""

    store: ExperienceStore
    building: str | None = None
    qsr_learned: dict[tuple[str, str], float] = field(default_factory=dict)

    def qsr_knowledge(self, base: QsrKnowledge) -> QsrKnowledge:
        """`base` with what earlier episodes learned (`ExperienceStore.qsr_for`)."""
        return self.store.qsr_for(base)

    def learn_qsr(self, descriptions: Iterable[QsrDescription]) -> None:
        """One observation more for each description (those a find credited)."""
        for d in descriptions:
            key = (d.target, qsr_chain_key(d.chain))
            self.qsr_learned[key] = self.qsr_learned.get(key, 0.0) + 1.0

    def with_learned(self, evidence: Evidence) -> Evidence:
        """`evidence` with this session's QSR observations."""
        return replace(evidence, qsr=dict(self.qsr_learned))
