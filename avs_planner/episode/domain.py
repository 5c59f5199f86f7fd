"""The AVS domain, read once, and UP problems built from a state without reparsing PDDL.

Reading PDDL through unified-planning takes about a second; the switching loop rebuilds its
problem after every action, so it copies the domain's fluents and actions into a fresh UP
`Problem` and sets objects and initial values directly.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from unified_planning.model import Object, Problem

from avs_planner.cp.task import Atom
from avs_planner.pddl import ProbabilisticProblem, read_text

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
    """A ProbabilisticProblem of the AVS domain with these objects, true atoms and values."""
    base = base_problem()
    up = base.problem
    em = up.environment.expression_manager
    problem = Problem(name, up.environment)
    for fluent in up.fluents:
        problem.add_fluent(fluent, default_initial_value=up.fluents_defaults.get(fluent))
    problem.add_actions(up.actions)
    for constant in up.all_objects:
        if str(constant.type) == "relation":  # the domain's constants `in` and `on`
            problem.add_object(constant)
    by_name = {o.name: o for o in problem.all_objects}
    for type_name, names in objects.items():
        user_type = up.user_type(type_name)
        for obj_name in names:
            by_name[obj_name] = Object(obj_name, user_type)
            problem.add_object(by_name[obj_name])

    def term(atom: Atom):  # noqa: ANN202 - a UP FNode
        fluent = up.fluent(atom[0])
        return em.FluentExp(fluent, [em.ObjectExp(by_name[a]) for a in atom[1:]])

    for atom in sorted(atoms):
        problem.set_initial_value(term(atom), em.TRUE())
    for atom, value in sorted(values.items()):
        problem.set_initial_value(term(atom), em.Real(_fraction(value)))
    problem.add_goal(term(goal))
    for metric in up.quality_metrics:
        problem.add_quality_metric(metric)
    return ProbabilisticProblem(problem, base.up_success, str(DOMAIN_FILE), f"<{name}>")


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


def _fraction(value: float):  # noqa: ANN202 - Fraction, exact for UP
    from fractions import Fraction

    return Fraction(round(float(value), 6)).limit_denominator(1_000_000)
