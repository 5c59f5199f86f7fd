"""Atoms no action can add: once false, they stay false, as a false static atom does.

Some dynamic fluents are added by the domain's actions for a part of their atoms only:
`in-room ?p ?r` is added by `assume-leads-to-room` for placeholders, never for ordinary
places; `virtual` is only ever deleted. An atom outside every add effect keeps the truth it
has in the state forever if it is false. So a positive precondition on such a fluent is
checked when the schemas are joined too (as static preconditions are), against the atoms some
action may add plus the true atoms that are not among them (the *pinned* atoms, part of the
structure's cache key): bindings that can never apply, from this state or any it leads to,
are not ground at all. They used to be ground and then dropped by the reachability pass (on a
20-place AVS problem, 8640 of 19112 rows: searches from places of other rooms).

The add effects are over-approximated by their parameters' types (an effect's other
preconditions are not read), so what is pruned is exactly what types rule out.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from unified_planning.model import Problem, Type

from avs_planner.cp.encoding import AtomSpace
from avs_planner.cp.schema import LiftedSchema
from avs_planner.cp.task import Atom

MAX_ADDABLE = 200_000  # a fluent whose addable atoms are more than this is left alone

NameSets = tuple[frozenset[str], ...]


@dataclass(frozen=True)
class AddLimits:
    """Per limited fluent, its add effects as one name set per argument (a product each)."""

    adds: Mapping[str, tuple[NameSets, ...]]
    _joined: dict[str, tuple[LiftedSchema, LiftedSchema]] = field(
        default_factory=dict, compare=False, repr=False)

    def addable(self, atom: Atom) -> bool:
        """True if an action may add this atom (always, for a fluent that is not limited)."""
        templates = self.adds.get(atom[0])
        if templates is None:
            return True
        args = atom[1:]
        return any(all(map(frozenset.__contains__, sets, args)) for sets in templates)

    def pinned(self, true_atoms: Iterable[Atom]) -> frozenset[Atom]:
        """The true atoms of limited fluents that no action adds (the cache key's part)."""
        if not self.adds:
            return frozenset()
        adds = self.adds
        return frozenset(a for a in true_atoms if a[0] in adds and not self.addable(a))

    def joined(self, schema: LiftedSchema) -> LiftedSchema:
        """The schema with its positive preconditions on limited fluents also checked by
        the join (they stay dynamic preconditions too: an action may delete them)."""
        hit = self._joined.get(schema.name)
        if hit is not None and hit[0] is schema:
            return hit[1]
        extra = tuple(t for t in schema.pre_pos if t[0] in self.adds)
        out = replace(schema, static_pos=schema.static_pos + extra) if extra else schema
        self._joined[schema.name] = (schema, out)
        return out

    def codes(self, space: AtomSpace, pinned: Iterable[Atom]) -> np.ndarray:
        """Codes of every atom a limited fluent may have true: addable or pinned."""
        parts = [space.encode_product(name, sets)
                 for name, templates in self.adds.items() for sets in templates]
        pinned_codes = [c for c in map(space.encode, pinned) if c is not None]
        parts.append(np.array(pinned_codes, dtype=np.int64))
        return np.concatenate(parts)


NO_LIMITS = AddLimits({})


def add_limits(problem: Problem, schemas: Sequence[LiftedSchema]) -> AddLimits:
    """The dynamic fluents read as positive preconditions that actions add only in part."""
    read = {t[0] for s in schemas if not s.never for t in s.pre_pos}
    if not read:
        return NO_LIMITS
    names = _names_by_type(problem)
    signature = {f.name: tuple(p.type for p in f.signature) for f in problem.fluents}
    adds: dict[str, list[NameSets]] = {name: [] for name in read}
    for schema in schemas:
        if schema.never:
            continue
        types = dict(zip(schema.params, schema.param_types, strict=True))
        for template in schema.add:
            if template[0] in adds:
                adds[template[0]].append(tuple(
                    names.get(str(types[t]), frozenset()) if t[0] == "?" else frozenset((t,))
                    for t in template[1:]))
    limited = {}
    for name, templates in adds.items():
        full = tuple(names.get(str(t), frozenset()) for t in signature[name])
        if any(all(map(frozenset.issuperset, sets, full)) for sets in templates):
            continue  # one effect adds every atom of the fluent
        if sum(_product(sets) for sets in templates) > MAX_ADDABLE:
            continue
        limited[name] = tuple(templates)
    return AddLimits(limited) if limited else NO_LIMITS


def _product(sets: NameSets) -> int:
    size = 1
    for s in sets:
        size *= len(s)
    return size


def _names_by_type(problem: Problem) -> dict[str, frozenset[str]]:
    """Object names of every type that has objects, subtypes included."""
    members: dict[str, set[str]] = {}
    for obj in problem.all_objects:
        ancestor: Type | None = obj.type
        while ancestor is not None:
            members.setdefault(str(ancestor), set()).add(obj.name)
            ancestor = ancestor.father  # type: ignore[attr-defined]
    return {k: frozenset(v) for k, v in members.items()}
