"""Fixtures for the continual planner tests: tiny hand-built probabilistic UP problems."""

from __future__ import annotations

import random
from fractions import Fraction
from pathlib import Path

import pytest
from unified_planning.shortcuts import (
    BoolType,
    Fluent,
    InstantaneousAction,
    Int,
    MinimizeActionCosts,
    Not,
    Problem,
    Real,
)

from avs_planner.pddl.model import ProbabilisticProblem
from tests.ipc import IPC, domain_for, ipc_domains

ROOT = Path(__file__).resolve().parents[3]
AVS_DOMAIN = ROOT / "domains" / "avs" / "domain.pddl"
CORRIDOR = ROOT / "domains" / "avs" / "problems" / "corridor.pddl"


def avs_and_ipc_makers() -> list[tuple[str, object]]:
    """(name, problem maker) of every AVS example problem and of each IPC domain's
    instance-1 (the domains it reads and solves today), for tests that compare two ways of
    grounding or planning on them."""
    from avs_planner.pddl import read_files

    cases: list[tuple[str, object]] = [
        (problem.stem, lambda p=problem: read_files(AVS_DOMAIN, p))
        for problem in sorted((AVS_DOMAIN.parent / "problems").glob("*.pddl"))
    ]
    for name in ipc_domains(solvable=True):
        instance = IPC / name / "instance-1.pddl"
        if instance.exists():
            domain = domain_for(instance)  # domain.pddl, or domain-1.pddl where one per instance
            cases.append((name, lambda d=domain, i=instance: read_files(d, i)))
    return cases


def random_problem(seed: int, n_fluents: int = 4, n_actions: int = 6) -> ProbabilisticProblem:
    """A propositional problem with random pre/add/del, costs 1..5, p in {1, .9, .6, .3}."""
    rng = random.Random(seed)
    problem = Problem(f"random{seed}")
    fluents = [Fluent(f"f{i}", BoolType()) for i in range(n_fluents)]
    for f in fluents:
        problem.add_fluent(f, default_initial_value=False)
    costs, success = {}, {}
    for j in range(n_actions):
        action = InstantaneousAction(f"a{j}")
        chosen = rng.sample(fluents, rng.randint(0, 2))
        for f in chosen:
            action.add_precondition(f() if rng.random() < 0.7 else Not(f()))
        for f in rng.sample(fluents, rng.randint(1, 2)):
            action.add_effect(f(), rng.random() < 0.7)
        problem.add_action(action)
        costs[action] = Int(rng.randint(1, 5))
        p = rng.choice([1, Fraction(9, 10), Fraction(6, 10), Fraction(3, 10)])
        if p != 1:
            success[action.name] = Real(Fraction(p))
    for f in fluents:
        if rng.random() < 0.3:
            problem.set_initial_value(f(), True)
    for f in rng.sample(fluents, 2):
        problem.add_goal(f())
    problem.add_quality_metric(MinimizeActionCosts(costs))
    return ProbabilisticProblem(problem, success)


@pytest.fixture(scope="session")
def corridor():
    from avs_planner.pddl import read_files

    return read_files(AVS_DOMAIN, CORRIDOR)


@pytest.fixture
def make_random():
    return random_problem
