"""The AVS domain, read once, and problems built from a state without reparsing PDDL.

The switching loop rebuilds its problem after every action, so it copies the domain's
fluents and actions into a fresh `Problem` of the same model as the domain's (the project's
own `pddl.lite`, as the reader builds it: an episode then never imports unified-planning;
UP's only if the reader had to read the domain with UP) and sets objects and initial values
directly, through the calls both models share.
"""

from __future__ import annotations

import importlib
from fractions import Fraction
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any

from avs_planner.cp.task import Atom
from avs_planner.pddl import ProbabilisticProblem, lite, read_text

DOMAIN_FILE = Path(__file__).resolve().parents[2] / "domains" / "avs" / "domain.pddl"

SEED_PROBLEM_FILE = DOMAIN_FILE.parent / "problems" / "corridor.pddl"


@cache
def domain_text() -> str:
    return DOMAIN_FILE.read_text(encoding="utf-8")


@cache
def base_problem() -> ProbabilisticProblem:
    """The domain with its example problem: the source of fluents, actions, success terms."""
    problem_text = SEED_PROBLEM_FILE.read_text(encoding="utf-8")
    return read_text(domain_text(), problem_text, str(DOMAIN_FILE), str(SEED_PROBLEM_FILE))


def build_problem(
    name: str,
    objects: dict[str, list[str]],
    atoms: frozenset[Atom],
    values: dict[Atom, float],
    goal: Atom,
) -> ProbabilisticProblem:
    """A ProbabilisticProblem of the AVS domain with these objects, true atoms and values,
    in the domain's model; a `lite` one gives UP's problem of the same state when asked
    (`.problem`, `.up_success`)."""
    base = base_problem()
    problem = _fill(base.model, name, objects, atoms, values, goal)
    if lite.is_lite(problem):
        kept = ({t: list(names) for t, names in objects.items()}, dict(values))
        problem.counterpart = lambda: (  # type: ignore[union-attr]
            _fill(base.problem, name, kept[0], atoms, kept[1], goal), base.up_success)
    # the actions are the domain's, so its success terms (nodes over their parameters) hold
    return ProbabilisticProblem(problem, base.success, str(DOMAIN_FILE), f"<{name}>")


def _fill(domain: Any, name: str, objects: dict[str, list[str]], atoms: frozenset[Atom],
          values: dict[Atom, float], goal: Atom) -> Any:
    """A problem of `domain`'s model (`lite`'s or UP's, through the calls both have) with the
    domain's fluents, actions, constants and metric, and these objects, atoms and goal."""
    kit = _model_kit(domain)
    em = domain.environment.expression_manager
    problem = kit.Problem(name, domain.environment)
    for fluent in domain.fluents:
        problem.add_fluent(fluent, default_initial_value=domain.fluents_defaults.get(fluent))
    problem.add_actions(domain.actions)
    for constant in domain.all_objects:
        if str(constant.type) == "relation":  # the domain's constants `in` and `on`
            problem.add_object(constant)
    by_name = {o.name: o for o in problem.all_objects}
    for type_name, names in objects.items():
        user_type = domain.user_type(type_name)
        for obj_name in names:
            by_name[obj_name] = kit.Object(obj_name, user_type)
            problem.add_object(by_name[obj_name])

    def term(atom: Atom) -> Any:  # a node of the domain's model
        fluent = domain.fluent(atom[0])
        return em.FluentExp(fluent, [em.ObjectExp(by_name[a]) for a in atom[1:]])

    for atom in sorted(atoms):
        problem.set_initial_value(term(atom), em.TRUE())
    for atom, value in sorted(values.items()):
        problem.set_initial_value(term(atom), em.Real(_fraction(value)))
    problem.add_goal(term(goal))
    for metric in domain.quality_metrics:
        problem.add_quality_metric(metric)
    return problem


def _model_kit(model: object) -> ModuleType:
    """The module whose `Problem` and `Object` make a problem of `model`'s kind: `lite`, or
    unified-planning's (imported only then: when the reader read the domain with UP, or
    when UP's counterpart of a `lite` problem is asked for)."""
    if lite.is_lite(model):
        return lite
    return importlib.import_module("unified_planning.model")


_SKELETONS: dict[tuple, ProbabilisticProblem] = {}
_SKELETON_CACHE = 32


def planning_problem(objects: dict[str, list[str]], goal: Atom) -> ProbabilisticProblem:
    """Objects and goal only, for a planner that takes the state as a `WorldState` (the CP's
    `replan`/`update`); the same object set gives the same problem object, so the CP's
    grounding cache recognises it without rehashing the domain."""
    key = (tuple((t, tuple(names)) for t, names in sorted(objects.items())), goal)
    problem = _SKELETONS.get(key)
    if problem is None:
        if len(_SKELETONS) >= _SKELETON_CACHE:
            _SKELETONS.pop(next(iter(_SKELETONS)))
        problem = _SKELETONS[key] = build_problem("episode", objects, frozenset(), {}, goal)
    return problem


def _fraction(value: float) -> Fraction:
    """The value as the exact fraction both models take for a real."""
    return Fraction(round(float(value), 6)).limit_denominator(1_000_000)
