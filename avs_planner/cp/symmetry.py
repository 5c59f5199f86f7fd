"""Interchangeable objects (e.g. the pre-allocated virtual `new-object1..k`) and pruning them.

Two objects of the same type are interchangeable when swapping their names maps the initial
state, the numeric values and the goal onto themselves and the domain never names either.
Then, in a state that the swap leaves unchanged, applying an action to the higher one leads
to a mirror image of applying it to the lower one (same cost, same probability), so the
search only tries the lower one.
"""

from __future__ import annotations

from collections import OrderedDict, defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
from unified_planning.model import FNode, Problem

from avs_planner.cp.task import Atom, GroundTask, WorldState
from avs_planner.pddl.model import ProbabilisticProblem

Pair = tuple[str, str]


def _swap(atom: Atom, a: str, b: str) -> Atom:
    return (atom[0], *(b if x == a else a if x == b else x for x in atom[1:]))


_NAMED: OrderedDict[int, tuple[ProbabilisticProblem, frozenset[str]]] = OrderedDict()


def _named_objects(pproblem: ProbabilisticProblem) -> frozenset[str]:
    """Objects the domain or the goal names explicitly (PDDL constants, goal arguments);
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
    problem = pproblem.problem
    roots: list[FNode] = list(problem.goals) + list(pproblem.success.values())
    for action in problem.actions:
        roots.extend(action.preconditions)
        for eff in action.effects:
            roots.extend((eff.fluent, eff.value, eff.condition))
    for metric in problem.quality_metrics:
        roots.extend(getattr(metric, "costs", {}).values())
    names: set[str] = set()
    stack = roots
    while stack:
        node = stack.pop()
        if node.is_object_exp():
            names.add(node.object().name)
        stack.extend(node.args)
    return names


def _mentions(state: WorldState) -> dict[str, list[Atom]]:
    index: dict[str, list[Atom]] = defaultdict(list)
    for atom in list(state.true_atoms) + list(state.values):
        for x in set(atom[1:]):
            index[x].append(atom)
    return index


def _interchangeable(a: str, b: str, state: WorldState, mentions) -> bool:
    atoms = set(mentions.get(a, ())) | set(mentions.get(b, ()))
    for atom in atoms:
        other = _swap(atom, a, b)
        if atom in state.true_atoms:
            if other not in state.true_atoms:
                return False
        elif state.values.get(atom) != state.values.get(other):
            return False
    return True


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
    problem: Problem = pproblem.problem
    named = _named_objects(pproblem)
    mentions = _mentions(state)
    by_type: dict[str, list[str]] = defaultdict(list)
    for obj in problem.all_objects:
        if obj.name not in named:
            by_type[str(obj.type)].append(obj.name)
    groups = []
    for names in by_type.values():
        groups.extend(_partition(names, state, mentions))
    groups = [g for g in groups if len(g) > 1]
    if not groups:
        return NO_SYMMETRIES
    return _build(task, groups)


def _partition(names: list[str], state: WorldState, mentions) -> list[tuple[str, ...]]:
    classes: list[list[str]] = []
    for name in names:
        for cls in classes:
            if _interchangeable(cls[0], name, state, mentions):
                cls.append(name)
                break
        else:
            classes.append([name])
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
    for i, atom in enumerate(task.facts):
        for x in set(atom[1:]):
            facts_of[x].append(i)
    for group in groups:
        for j, b in enumerate(group):
            for a in group[:j]:
                touched = sorted(set(facts_of[a]) | set(facts_of[b]))
                fact_pairs[(a, b)] = tuple(
                    (f, task.fact_index.get(_swap(task.facts[f], a, b), -1)) for f in touched
                )
    by_args: dict[tuple[str, ...], tuple[Pair, ...]] = {}
    _FACT_PAIRS[key] = (task.facts, fact_pairs, by_args)  # a strong ref keeps the id unique
    while len(_FACT_PAIRS) > _FACT_PAIRS_SIZE:
        _FACT_PAIRS.popitem(last=False)
    return fact_pairs, by_args


def _build(task: GroundTask, groups: Iterable[tuple[str, ...]]) -> Symmetries:
    groups = tuple(groups)
    fact_pairs, by_args = _fact_pairs(task, groups)
    lower = {b: [(a, b) for a in group[:j]] for group in groups for j, b in enumerate(group)}
    higher = frozenset(b for b, pairs in lower.items() if pairs)
    arrays = task.arrays
    if arrays is not None and arrays.arg_ids is not None:
        grouped = _checks_from_ids(arrays, lower, higher, by_args)
        hit, inverse, pair_lists = grouped
        checks = dict(zip(hit.tolist(), map(pair_lists.__getitem__, inverse.tolist()),
                          strict=True))
        return Symmetries(groups, fact_pairs, checks, grouped)
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
