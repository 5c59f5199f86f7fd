"""Matching newly observed real objects to the virtual objects a plan assumed.

The plan's assumptive steps describe each virtual object by the atoms they add with it as the
subject, i.e. first argument (e.g. `(label-of new-object1 table)`, `(related new-object1 in
room3)`; not `(related new-object2 on new-object1)`, which describes new-object2). A real
object matches when, with its name put in place of the virtual one, every described atom of a
predicate the observation speaks about is among the observed atoms. Matching is one-to-one
and follows the plan's order, so it is deterministic.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import replace

from avs_planner.cp.search import PlanStep
from avs_planner.cp.task import Atom, GroundTask

VIRTUAL_PREFIX = "new-"


def is_virtual_name(name: str) -> bool:
    """The AVS convention: pre-allocated virtual objects are called new-room1, new-object1, ..."""
    return name.lower().startswith(VIRTUAL_PREFIX)


def assumed_descriptions(
    plan: Sequence[PlanStep], task: GroundTask, is_virtual: Callable[[str], bool]
) -> dict[str, set[Atom]]:
    """For each virtual object in the plan (plan order), the atoms assumptive steps add about
    it as their subject."""
    described: dict[str, set[Atom]] = {}
    for step in plan:
        for arg in step.args:
            if is_virtual(arg):
                described.setdefault(arg, set())
        action = task.action(step.name, step.args)
        if not step.assumptive or action is None:
            continue
        for i in action.add_facts:
            atom = task.facts[i]
            if len(atom) > 1 and atom[1] in described:
                described[atom[1]].add(atom)
    return described


def _rename(atom: Atom, old: str, new: str) -> Atom:
    return (atom[0], *(new if x == old else x for x in atom[1:]))


def _matches(description: set[Atom], virtual: str, real: str, observed: set[Atom]) -> bool:
    predicates = {a[0] for a in observed}
    relevant = [_rename(a, virtual, real) for a in description if a[0] in predicates]
    return bool(relevant) and all(a in observed for a in relevant)


def match_virtual_objects(
    plan: Sequence[PlanStep],
    task: GroundTask,
    observations: Mapping[str, Iterable[Atom]],
    is_virtual: Callable[[str], bool] = is_virtual_name,
) -> dict[str, str]:
    """Map virtual objects of `plan` to observed real objects (name -> atoms about it)."""
    described = assumed_descriptions(plan, task, is_virtual)
    free = {real: set(atoms) for real, atoms in sorted(observations.items())}
    mapping: dict[str, str] = {}
    for virtual, description in described.items():
        for real, atoms in free.items():
            if _matches(description, virtual, real, atoms):
                mapping[virtual] = real
                del free[real]
                break
    return mapping


def rename_plan(plan: Sequence[PlanStep], mapping: Mapping[str, str]) -> list[PlanStep]:
    """The plan with virtual objects replaced by the real objects they were matched to."""
    return [replace(s, args=tuple(mapping.get(a, a) for a in s.args)) for s in plan]
