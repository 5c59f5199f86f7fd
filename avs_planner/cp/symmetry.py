"""Interchangeable objects (e.g. the pre-allocated virtual `new-object1..k`) and pruning them.

Two objects of the same type are interchangeable when swapping their names maps the initial
state, the numeric values and the goal onto themselves and the domain never names either.
Then, in a state that the swap leaves unchanged, applying an action to the higher one leads
to a mirror image of applying it to the lower one (same cost, same probability), so the
search only tries the lower one.
"""

from __future__ import annotations

from collections import OrderedDict, defaultdict
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.task import Atom, GroundTask, WorldState
from avs_planner.pddl.model import ProbabilisticProblem

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import FNode, Problem

Pair = tuple[str, str]


def _swapped(atom: Atom, swap: Callable[[str, str], str]) -> Atom:
    """The atom with two objects exchanged; `swap` is `{a: b, b: a}.get`."""
    return (atom[0], *map(swap, atom[1:], atom[1:]))


_NAMED: OrderedDict[int, tuple[ProbabilisticProblem, frozenset[str]]] = OrderedDict()


def _named_objects(pproblem: ProbabilisticProblem) -> frozenset[str]:
    """Objects the domain or the goal names explicitly (PDDL constants, goal arguments; a
    derived predicate's rule is part of the domain: the closure of a state is then mirrored
    by a swap of two objects no rule names, as derived facts are facts of the task);
    kept for the last few problem objects (a problem is not changed once planned)."""
    hit = _NAMED.get(id(pproblem))
    if hit is not None and hit[0] is pproblem:
        return hit[1]
    names = frozenset(_walk_named(pproblem))
    _NAMED[id(pproblem)] = (pproblem, names)
    while len(_NAMED) > 16:
        _NAMED.popitem(last=False)
    return names


def _walk_named(pproblem: ProbabilisticProblem) -> set[str]:
    problem = pproblem.model
    roots: list[FNode] = list(problem.goals) + list(pproblem.success.values())
    for action in problem.actions:
        roots.extend(action.preconditions)
        for eff in action.effects:
            roots.extend((eff.fluent, eff.value, eff.condition))
    for metric in problem.quality_metrics:
        roots.extend(getattr(metric, "costs", {}).values())
    roots.extend(axiom.body for axiom in getattr(problem, "axioms", ()))  # derived predicates
    names: set[str] = set()
    stack = roots
    while stack:
        node = stack.pop()
        if node.is_object_exp():
            names.add(node.object().name)
        stack.extend(node.args)
    return names


def _mentions(state: WorldState, candidates: set[str]) -> dict[str, list[Atom]]:
    """Per candidate object, the distinct atoms of the state (true or valued) naming it."""
    index: dict[str, list[Atom]] = defaultdict(list)
    true_atoms = state.true_atoms
    for atoms, valued in ((true_atoms, False), (state.values, True)):
        for atom in atoms:
            args = atom[1:]
            if candidates.isdisjoint(args) or (valued and atom in true_atoms):
                continue
            for x in candidates.intersection(args):
                index[x].append(atom)
    return index


def _interchangeable(a: str, b: str, state: WorldState, mentions) -> bool:
    """True if swapping a and b maps the state's true atoms and values onto themselves.
    a's atoms are tried first, then b's (together, the atoms naming either), so that most
    pairs that are not interchangeable fail after a few atoms."""
    true_atoms, values = state.true_atoms, state.values
    swap = {a: b, b: a}.get
    return all(_kept(atom, _swapped(atom, swap), true_atoms, values)
               for x in (a, b) for atom in mentions.get(x, ()))


def _kept(atom: Atom, other: Atom, true_atoms: frozenset[Atom], values) -> bool:
    if atom in true_atoms:
        return other in true_atoms
    return values.get(atom) == values.get(other)


@dataclass(frozen=True)
class Symmetries:
    """Groups of interchangeable objects and, per pair, the fact pairs the swap exchanges."""

    groups: tuple[tuple[str, ...], ...]
    fact_pairs: Mapping[Pair, tuple[tuple[int, int], ...]]
    checks: Mapping[int, tuple[Pair, ...]]  # action index -> pairs that may prune it
    grouped: tuple | None = field(default=None, compare=False, repr=False)
    """`checks` in array form when built from the task's arrays: (actions, ascending; the
    index of each one's pairs in `pair_lists`; pair_lists), for the native packer."""

    def prunes(self, action_index: int, state: int) -> bool:
        """True if a lower interchangeable object makes this action redundant in `state`."""
        for pair in self.checks.get(action_index, ()):
            if all((state >> f & 1) == (g >= 0 and state >> g & 1)
                   for f, g in self.fact_pairs[pair]):
                return True
        return False


NO_SYMMETRIES = Symmetries((), {}, {})


def find_symmetries(
    pproblem: ProbabilisticProblem, state: WorldState, task: GroundTask
) -> Symmetries:
    """Interchangeable object groups of this task in this state (none if nothing is)."""
    problem: Problem = pproblem.model
    named = _named_objects(pproblem)
    by_type: dict[str, list[str]] = defaultdict(list)
    for obj in problem.all_objects:
        if obj.name not in named:
            by_type[str(obj.type)].append(obj.name)
    candidates = {x for names in by_type.values() if len(names) > 1 for x in names}
    mentions = _mentions(state, candidates)
    groups = []
    for names in by_type.values():
        groups.extend(_partition(names, state, mentions))
    groups = [g for g in groups if len(g) > 1]
    if not groups:
        return NO_SYMMETRIES
    return _build(task, groups)


def _partition(names: list[str], state: WorldState, mentions) -> list[tuple[str, ...]]:
    """Classes of interchangeable objects, ordered by first member. Interchangeability is an
    equivalence (the swaps that keep the state form a group), so objects are first split by
    the number of distinct atoms naming them (a swap that keeps the state maps a's atoms one
    to one onto b's) and compared only within a split, each with the first member of a
    class."""
    if len(names) < 2:
        return [tuple(names)]
    by_count: dict[int, list[str]] = defaultdict(list)
    for name in names:
        by_count[len(mentions.get(name, ()))].append(name)
    classes: list[list[str]] = []
    for bucket in by_count.values():
        found: list[list[str]] = []
        for name in bucket:
            for cls in found:
                if _interchangeable(cls[0], name, state, mentions):
                    cls.append(name)
                    break
            else:
                found.append([name])
        classes.extend(found)
    position = {name: i for i, name in enumerate(names)}
    classes.sort(key=lambda c: position[c[0]])
    return [tuple(c) for c in classes]


_FACT_PAIRS: OrderedDict[tuple, tuple[tuple, dict, dict]] = OrderedDict()
_FACT_PAIRS_SIZE = 8


def _fact_pairs(task: GroundTask, groups: tuple[tuple[str, ...], ...]) -> tuple[dict, dict]:
    """Per pair (a, b) of a group, the facts mentioning a or b and their swapped images;
    depends only on the fact table, so it is kept for the last few (fact table, groups),
    with a memo of the pairs that may prune an action, by its arguments."""
    key = (id(task.facts), groups)
    hit = _FACT_PAIRS.get(key)
    if hit is not None and hit[0] is task.facts:
        _FACT_PAIRS.move_to_end(key)
        return hit[1], hit[2]
    fact_pairs: dict[Pair, tuple[tuple[int, int], ...]] = {}
    facts_of: dict[str, list[int]] = defaultdict(list)
    members = {x for group in groups for x in group}
    for i, atom in enumerate(task.facts):
        if members.isdisjoint(atom):  # most facts name no grouped object
            continue
        for x in members.intersection(atom[1:]):
            facts_of[x].append(i)
    for group in groups:
        for j, b in enumerate(group):
            for a in group[:j]:
                touched = sorted(set(facts_of[a]) | set(facts_of[b]))
                swap, facts, index = {a: b, b: a}.get, task.facts, task.fact_index.get
                fact_pairs[(a, b)] = tuple(
                    (f, index(_swapped(atom, swap), -1))
                    for f, atom in zip(touched, map(facts.__getitem__, touched), strict=True)
                )
    by_args: dict[tuple[str, ...], tuple[Pair, ...]] = {}
    _FACT_PAIRS[key] = (task.facts, fact_pairs, by_args)  # a strong ref keeps the id unique
    while len(_FACT_PAIRS) > _FACT_PAIRS_SIZE:
        _FACT_PAIRS.popitem(last=False)
    return fact_pairs, by_args


def _build(task: GroundTask, groups: Iterable[tuple[str, ...]]) -> Symmetries:
    """The symmetries of these groups; the last ones are kept with a grounder's action
    table (its `memo`): a replan that reuses the table often has the same groups."""
    groups = tuple(groups)
    memo = getattr(task.actions, "memo", None)
    if memo is not None:
        hit = memo.get("symmetries")
        if hit is not None and hit[0] is task.facts and hit[1] == groups:
            return hit[2]
    symmetries = _build_new(task, groups)
    if memo is not None:
        memo["symmetries"] = (task.facts, groups, symmetries)
    return symmetries


def _build_new(task: GroundTask, groups: tuple[tuple[str, ...], ...]) -> Symmetries:
    fact_pairs, by_args = _fact_pairs(task, groups)
    lower = {b: [(a, b) for a in group[:j]] for group in groups for j, b in enumerate(group)}
    higher = frozenset(b for b, pairs in lower.items() if pairs)
    arrays = task.arrays
    if arrays is not None and arrays.arg_ids is not None:
        grouped = _checks_from_ids(arrays, lower, higher, by_args)
        return Symmetries(groups, fact_pairs, _Checks(grouped), grouped)
    checks = {}
    for action in task.actions:
        args = action.args
        if higher.isdisjoint(args):
            continue
        pairs = by_args.get(args)
        if pairs is None:
            pairs = by_args[args] = tuple(
                p for x in dict.fromkeys(args) for p in lower.get(x, ())
            )
        checks[action.index] = pairs
    return Symmetries(groups, fact_pairs, checks)


class _Checks(Mapping[int, tuple[Pair, ...]]):
    """`Symmetries.checks` of grouped arrays, as a dict built on first lookup: the native
    core reads `grouped` and never looks (the dict cost ~0.6 ms on 20-place AVS problems)."""

    __slots__ = ("_grouped", "_table")

    def __init__(self, grouped: tuple):
        self._grouped = grouped
        self._table: dict[int, tuple[Pair, ...]] | None = None

    def _dict(self) -> dict[int, tuple[Pair, ...]]:
        if self._table is None:
            hit, inverse, pair_lists = self._grouped
            self._table = dict(zip(hit.tolist(), map(pair_lists.__getitem__, inverse.tolist()),
                                   strict=True))
        return self._table

    def __getitem__(self, action_index: int) -> tuple[Pair, ...]:
        return self._dict()[action_index]

    def get(self, action_index, default=None):
        return self._dict().get(action_index, default)

    def __iter__(self) -> Iterator[int]:
        return iter(self._dict())

    def __len__(self) -> int:
        return len(self._grouped[0])

    def __repr__(self) -> str:
        return repr(self._dict())


def _checks_from_ids(arrays, lower, higher, by_args) -> tuple:
    """`checks` from the task's argument-id matrix, without building the actions, as
    (actions, index into the pair lists per action, pair lists). An
    action's pairs depend only on which higher objects it names, in order, so the rows are
    reduced to those (others -1) and the pairs found once per distinct reduced row;
    `by_args` memoises them per reduced id tuple."""
    names = arrays.objects
    is_higher = np.zeros(len(names) + 1, dtype=bool)  # the last slot is the -1 padding
    is_higher[[i for i, name in enumerate(names) if name in higher]] = True
    ids = arrays.arg_ids
    none = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), [])
    if not ids.size:
        return none
    marked = is_higher[ids]
    hit = np.flatnonzero(marked.any(axis=1))
    if not len(hit):
        return none
    reduced = np.where(marked[hit], ids[hit], -1)
    base = len(names) + 1
    if base ** reduced.shape[1] < 2**62:  # one int64 key per row: a 1-D unique is ~10x faster
        powers = base ** np.arange(reduced.shape[1], dtype=np.int64)
        _, first, inverse = np.unique((reduced + 1) @ powers, return_index=True,
                                      return_inverse=True)
        distinct = reduced[first]
    else:
        distinct, inverse = np.unique(reduced, axis=0, return_inverse=True)
    pairs_of = []
    for row in map(tuple, distinct.tolist()):
        pairs = by_args.get(row)
        if pairs is None:
            pairs = by_args[row] = tuple(
                p for x in dict.fromkeys(row) if x >= 0 for p in lower.get(names[x], ())
            )
        pairs_of.append(pairs)
    return hit, inverse.ravel(), pairs_of
