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
from collections.abc import Set as AbstractSet
from dataclasses import replace

from avs_planner.cp.search import PlanStep
from avs_planner.cp.task import Atom, GroundTask

VIRTUAL_PREFIX = "new-"


def is_virtual_name(name: str) -> bool:
    """The AVS convention: pre-allocated virtual objects are called new-room1, new-object1, ..."""
    return name.lower().startswith(VIRTUAL_PREFIX)


def _tasks(task: GroundTask | Sequence[GroundTask]) -> Sequence[GroundTask]:
    return [task] if isinstance(task, GroundTask) else task


def _first_action(tasks: Sequence[GroundTask], step: PlanStep):  # noqa: ANN202
    """(task, ground action) from the first task that has the step, or (None, None)."""
    found = ((t, t.action(step.name, step.args)) for t in tasks)
    return next(((t, a) for t, a in found if a is not None), (None, None))


def assumed_descriptions(
    plan: Sequence[PlanStep], task: GroundTask | Sequence[GroundTask],
    is_virtual: Callable[[str], bool]
) -> dict[str, set[Atom]]:
    """For each virtual object in the plan (plan order), the atoms assumptive steps add about
    it as their subject. With several tasks, a step's effects come from the first that has
    it (an assumption that came true is no longer possible in the current task)."""
    described: dict[str, set[Atom]] = {}
    tasks = _tasks(task)
    for step in plan:
        for arg in step.args:
            if is_virtual(arg):
                described.setdefault(arg, set())
        if not step.assumptive:
            continue
        owner, action = _first_action(tasks, step)
        if owner is None or action is None:
            continue
        for i in action.add_facts:
            atom = owner.facts[i]
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
    task: GroundTask | Sequence[GroundTask],
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


def confirmed_assumptions(
    plan: Sequence[PlanStep],
    tasks: Sequence[GroundTask],
    true_atoms: AbstractSet[Atom],
    mapping: Mapping[str, str] | None = None,
) -> list[int]:
    """Indices of the plan's assumptive steps that came true: every atom the step adds (with
    matched virtual objects renamed to their real objects) already holds. Such a step has
    nothing left to assume; kept, it would fail its own precondition (e.g. `(virtual ?o)`
    after the match) and force a needless replan, so the caller drops it. A step's effects
    are looked up in the first of `tasks` that has it (the current task may no longer hold
    an assumption that is now impossible because it came true; an earlier one does)."""
    mapping = mapping or {}
    out = []
    for i, step in enumerate(plan):
        if not step.assumptive:
            continue
        task, action = _first_action(tasks, step)
        if task is None or action is None or not action.add_facts:
            continue
        atoms = [task.facts[f] for f in action.add_facts]
        renamed = [(a[0], *(mapping.get(x, x) for x in a[1:])) for a in atoms]
        if all(a in true_atoms for a in renamed):
            out.append(i)
    return out


def rename_plan(plan: Sequence[PlanStep], mapping: Mapping[str, str]) -> list[PlanStep]:
    """The plan with virtual objects replaced by the real objects they were matched to."""
    return [replace(s, args=tuple(mapping.get(a, a) for a in s.args)) for s in plan]
