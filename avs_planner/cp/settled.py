"""What a state settles for good, checked when the schemas are joined (as static atoms are).

Two kinds of atoms rule ground actions out from a state and from every state it leads to:

* **Atoms no action adds.** Some dynamic fluents are added by the domain's actions for a part
  of their atoms only: `in-room ?p ?r` is added by `assume-leads-to-room` for placeholders,
  never for ordinary places; `virtual` is only ever deleted. An atom outside every add effect
  that is false stays false. A positive precondition on such a fluent is checked by the join
  against the atoms some action may add plus the true atoms that are not among them (the
  *pinned* atoms). Add effects are over-approximated by their parameters' types (an effect's
  other preconditions are not read).
* **Success probabilities that are 0.** When an action's success probability is one static
  numeric fluent term (the AVS domain's `p-obj-on ?l ?sl ?c`), an atom valued 0 makes every
  binding that reads it an action that never succeeds; the grounder dropped those after
  evaluating them. The join leaves them out (the *zero* atoms). An atom without a value is
  not ruled out: evaluating it later names it as missing, as before.

Both sets of atoms are part of the cached structure's key (`SettledAtoms.key`). What the join
leaves out is what the grounder's reachability pass and probability check dropped before,
after paying for its rows (on a 20-place AVS problem, 11,914 of 19,112 rows): the ground task
is the same.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.encoding import AtomSpace, fluent_template, objects_by_type
from avs_planner.cp.schema import AtomTemplate, LiftedSchema
from avs_planner.cp.task import Atom, WorldState

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import Problem, Type

MAX_ADDABLE = 200_000  # a fluent whose addable atoms are more than this is left alone

NameSets = tuple[frozenset[str], ...]
Key = tuple[frozenset[Atom], frozenset[Atom]]  # (pinned, zeros)
NO_KEY: Key = (frozenset(), frozenset())


@dataclass(frozen=True)
class SettledAtoms:
    """Per limited fluent, its add effects as one name set per argument (a product each);
    per schema whose success probability is a static fluent term, that term."""

    adds: Mapping[str, tuple[NameSets, ...]]
    odds: Mapping[str, AtomTemplate] = field(default_factory=dict)
    checks: Mapping[str, tuple[AtomTemplate, ...]] = field(default_factory=dict)
    """Per schema, its positive preconditions on limited fluents that some binding may make
    an atom no add effect covers (the others can never rule a binding out)."""
    _joined: dict[str, tuple[LiftedSchema, AtomTemplate | None, LiftedSchema]] = field(
        default_factory=dict, compare=False, repr=False)

    @cached_property
    def odds_fluents(self) -> frozenset[str]:
        return frozenset(t[0] for t in self.odds.values())

    def addable(self, atom: Atom) -> bool:
        """True if an action may add this atom (always, for a fluent that is not limited)."""
        templates = self.adds.get(atom[0])
        if templates is None:
            return True
        args = atom[1:]
        return any(all(map(frozenset.__contains__, sets, args)) for sets in templates)

    def pinned(self, true_atoms: Iterable[Atom]) -> frozenset[Atom]:
        """The true atoms of limited fluents that no action adds."""
        if not self.adds:
            return frozenset()
        adds = self.adds
        return frozenset(a for a in true_atoms if a[0] in adds and not self.addable(a))

    def zeros(self, values: Mapping[Atom, float]) -> frozenset[Atom]:
        """The atoms of success-probability fluents valued 0."""
        if not self.odds:
            return frozenset()
        names = self.odds_fluents
        return frozenset(a for a, v in values.items() if v == 0 and a[0] in names)

    def key(self, state: WorldState) -> Key:
        """What of `state` the join reads: (pinned atoms, zero atoms)."""
        if not self.adds and not self.odds:
            return NO_KEY
        return self.pinned(state.true_atoms), self.zeros(state.values)

    def joined(self, schema: LiftedSchema, key: Key) -> LiftedSchema:
        """The schema with its `checks` also checked by the join (they stay dynamic
        preconditions too: an action may delete them) and, if its success probability is a
        static fluent term of which `key` has zero atoms, that term checked not to be 0.
        Each check costs the join a little, so none is added that cannot rule out a binding."""
        odds = self.odds.get(schema.name)
        if odds is not None and not any(a[0] == odds[0] for a in key[1]):
            odds = None
        hit = self._joined.get(schema.name)
        if hit is not None and hit[0] is schema and hit[1] == odds:
            return hit[2]
        extra = self.checks.get(schema.name, ())
        out = schema
        if extra or odds is not None:
            out = replace(schema, static_pos=schema.static_pos + extra,
                          static_neg=schema.static_neg + ((odds,) if odds else ()))
        self._joined[schema.name] = (schema, odds, out)
        return out

    def codes(self, space: AtomSpace, key: Key) -> np.ndarray:
        """Codes the join reads as "in": every atom a limited fluent may have true (addable
        or pinned), and the zero atoms (read by the negated probability terms)."""
        parts = [space.encode_product(name, sets)
                 for name, templates in self.adds.items() for sets in templates]
        pinned, zeros = key
        parts.append(space.encode_all((*pinned, *zeros)))
        return np.concatenate(parts)


NOTHING_SETTLED = SettledAtoms({})


def settled_atoms(problem: Problem, schemas: Sequence[LiftedSchema],
                  static_names: frozenset[str]) -> SettledAtoms:
    """The limited fluents read as positive preconditions, and the schemas whose success
    probability is one static fluent term."""
    odds = {}
    for schema in schemas:
        template = fluent_template(schema.probability)
        if not schema.never and template is not None and template[0] in static_names:
            odds[schema.name] = template
    names = _names_by_type(problem)
    adds = _limited_adds(problem, schemas, names)
    checks = {}
    for schema in schemas:
        if schema.never:
            continue
        types = dict(zip(schema.params, schema.param_types, strict=True))
        useful = tuple(t for t in schema.pre_pos if t[0] in adds and not any(
            all(map(frozenset.issuperset, sets, _sets_of(
                tuple(types[x] if x[0] == "?" else x for x in t[1:]), names)))
            for sets in adds[t[0]]))
        if useful:
            checks[schema.name] = useful
    used = {t[0] for templates in checks.values() for t in templates}
    adds = {k: v for k, v in adds.items() if k in used}
    if not adds and not odds:
        return NOTHING_SETTLED
    return SettledAtoms(adds, odds, checks)


def _limited_adds(problem: Problem, schemas: Sequence[LiftedSchema],
                  names: Mapping[str, frozenset[str]]) -> dict[str, tuple[NameSets, ...]]:
    """Per limited fluent, its add effects as name sets."""
    read = {t[0] for s in schemas if not s.never for t in s.pre_pos}
    if not read:
        return {}
    signature = {f.name: tuple(p.type for p in f.signature) for f in problem.fluents}
    adds: dict[str, list[tuple[Type | str, ...]]] = {name: [] for name in read}
    for schema in schemas:
        if schema.never:
            continue
        types = dict(zip(schema.params, schema.param_types, strict=True))
        for effect in schema.conditional:
            types.update(effect.variables)
        templates = [*schema.add, *(e.atom for e in schema.conditional if e.adds)]
        for template in templates:
            if template[0] in adds:
                adds[template[0]].append(
                    tuple(types[t] if t[0] == "?" else t for t in template[1:]))

    limited = {}
    for name, templates in adds.items():
        full = tuple(names.get(str(t), frozenset()) for t in signature[name])
        name_sets = tuple(_sets_of(terms, names) for terms in templates)
        if any(all(map(frozenset.issuperset, sets, full)) for sets in name_sets):
            continue  # one effect adds every atom of the fluent
        if sum(_product(sets) for sets in name_sets) > MAX_ADDABLE:
            continue
        limited[name] = name_sets
    return limited


def _sets_of(terms: tuple[Type | str, ...], names: Mapping[str, frozenset[str]]) -> NameSets:
    """Per term, the names it may take: a type's objects or a constant."""
    return tuple(frozenset((t,)) if isinstance(t, str) else names.get(str(t), frozenset())
                 for t in terms)


def _product(sets: NameSets) -> int:
    size = 1
    for s in sets:
        size *= len(s)
    return size


def _names_by_type(problem: Problem) -> dict[str, frozenset[str]]:
    """Object names of every type that has objects, subtypes included."""
    names = [o.name for o in problem.all_objects]
    return {k: frozenset(names[i] for i in ids.tolist())
            for k, ids in objects_by_type(problem).items()}
