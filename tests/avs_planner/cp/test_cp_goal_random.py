"""Random goal formulas against a breadth-first search of the whole state space: on two small
domains (one with derived predicates), a goal has a plan exactly when some reachable state
satisfies it (by the naive evaluator, `derived_semantics.py`), and A* with h^max (admissible
through the goal's rules) finds one of the shortest length, in both engines."""

from __future__ import annotations

import itertools
import random
from collections.abc import Iterator
from pathlib import Path

import pytest

from avs_planner.cp import native
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanStatus, SearchOptions
from avs_planner.pddl import read_text
from tests.avs_planner.cp.derived_semantics import Atom, Semantics
from tests.avs_planner.cp.pddl_cases import LIFT, lift_problem

ENGINES = ["python", "native"] if native.AVAILABLE else ["python"]
DATA = Path(__file__).parent / "data" / "axioms"
BLOCKS = (DATA / "blocks-domain.pddl").read_text()
BLOCKS_PROBLEM = (DATA / "blocks-1-problem.pddl").read_text()

# per domain: predicates with their argument types, and the objects of each type
LIFT_WORLD = ({"at": ("passenger", "floor"), "served": ("passenger",), "in": ("passenger",),
               "lift-at": ("floor",)},
              {"passenger": ["p1", "p2"], "floor": ["f0", "f1", "f2"]})
BLOCKS_WORLD = ({"on": ("block", "block"), "ontable": ("block",), "holding": ("block",),
                 "clear": ("block",), "handempty": (), "above": ("block", "block")},
                {"block": ["a", "b", "c"]})


def random_goal(rng: random.Random, world: tuple[dict, dict], depth: int = 3,
                scope: tuple[tuple[str, str], ...] = ()) -> str:
    """A goal description: atoms, not, and, or, imply, exists, forall, = (of variables)."""
    predicates, objects = world
    connectives = ["not", "and", "or", "or", "imply", "exists", "exists", "forall"]
    kinds = (["atom"] * (2 if scope or depth < 3 else 0) + connectives) if depth else ["atom"]
    if scope:
        kinds.append("=")
    kind = rng.choice(kinds)
    if kind == "atom":
        name = rng.choice(sorted(predicates))
        args = []
        for type_ in predicates[name]:
            bound = [v for v, t in scope if t == type_]
            args.append(rng.choice(bound + objects[type_]) if bound and rng.random() < 0.7
                        else rng.choice(objects[type_]))
        return f"({' '.join([name, *args])})"
    if kind == "=":  # a variable and another of its type, or an object of it
        x, type_ = rng.choice(scope)
        return f"(= {x} {rng.choice([v for v, t in scope if t == type_] + objects[type_])})"
    if kind == "not":
        return f"(not {random_goal(rng, world, depth - 1, scope)})"
    if kind in ("and", "or"):
        parts = [random_goal(rng, world, depth - 1, scope) for _ in range(rng.randint(2, 3))]
        return f"({kind} {' '.join(parts)})"
    if kind == "imply":
        return (f"(imply {random_goal(rng, world, depth - 1, scope)} "
                f"{random_goal(rng, world, depth - 1, scope)})")
    type_ = rng.choice(sorted(objects))
    variable = f"?v{len(scope)}"
    body = random_goal(rng, world, depth - 1, (*scope, (variable, type_)))
    return f"({kind} ({variable} - {type_}) {body})"


class StateSpace:
    """Every state reachable from :init, with its distance, by the naive semantics."""

    def __init__(self, reference: Semantics):
        self.reference = reference
        start = frozenset(reference.initial())
        self.depth: dict[frozenset[Atom], int] = {start: 0}
        frontier = [start]
        while frontier:
            following = []
            for state in frontier:
                for name, args in self._applicable(state):
                    nxt = frozenset(reference.apply(set(state), name, args))
                    if nxt not in self.depth:
                        self.depth[nxt] = self.depth[state] + 1
                        following.append(nxt)
            frontier = following

    def _applicable(self, state: frozenset[Atom]) -> Iterator[tuple[str, tuple[str, ...]]]:
        problem = self.reference.problem
        for action in problem.actions:
            pools = [[o.name for o in problem.objects(p.type)] for p in action.parameters]
            for args in itertools.product(*pools):
                binding = {"p:" + p.name: x for p, x in zip(action.parameters, args,
                                                           strict=True)}
                if all(self.reference.holds(c, set(state), binding)
                       for c in action.preconditions):
                    yield action.name, args

    def shortest(self, reference: Semantics) -> int | None:
        """The distance of the nearest state where `reference`'s goal holds, if any."""
        return min((d for s, d in self.depth.items() if reference.goal_holds(set(s))),
                   default=None)


CASES = [("lift", seed) for seed in range(80)] + [("blocks", seed) for seed in range(80)]
_SPACES: dict[str, StateSpace] = {}


def _texts(kind: str, goal: str) -> tuple[str, str]:
    if kind == "lift":
        return LIFT, lift_problem(goal)
    return BLOCKS, BLOCKS_PROBLEM.replace("(:goal (and (above c a) (ontable b)))",
                                          f"(:goal {goal})")


@pytest.mark.parametrize(("kind", "seed"), CASES, ids=[f"{k}-{s}" for k, s in CASES])
def test_a_random_goal_is_reached_in_the_fewest_steps_exactly_when_reachable(
        kind: str, seed: int) -> None:
    rng = random.Random(seed)
    for _ in range(100):  # a goal :init does not satisfy already (most do)
        goal = random_goal(rng, LIFT_WORLD if kind == "lift" else BLOCKS_WORLD)
        task = read_text(*_texts(kind, goal))
        reference = Semantics(task.model)
        if not reference.goal_holds(reference.initial()):
            break
    space = _SPACES.get(kind)
    if space is None:
        space = _SPACES[kind] = StateSpace(reference)
    shortest = space.shortest(reference)
    results = [plan(task, SearchOptions(engine=e, heuristic="hmax", weight=1.0))
               for e in ENGINES]
    assert len({(r.status, tuple(s.label for s in r.plan), r.expanded) for r in results}) == 1
    found = results[0]
    if shortest is None:
        assert found.status is PlanStatus.UNSOLVABLE, goal
        return
    assert found.status is PlanStatus.SOLVED, goal
    assert len(found.plan) == shortest, goal
    reference.check_plan([(s.name, tuple(s.args)) for s in found.plan])
