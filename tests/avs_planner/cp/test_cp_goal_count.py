"""The greedy phase's goal-count open list (LAMA's alternation of open lists, with the goal
count where LAMA counts landmarks) and its search without commutation pruning."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from unified_planning.engines.plan_validator import SequentialPlanValidator

from avs_planner.cp import native
from avs_planner.cp.anytime import GREEDY_WEIGHT, Variant, greedy_search, unit_cost
from avs_planner.cp.grounding import ground
from avs_planner.cp.search import PlanStatus, SearchOptions, search
from avs_planner.cp.symmetry import NO_SYMMETRIES
from avs_planner.pddl import read_files
from avs_planner.up_engine import to_up_plan

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def maintenance():
    """20 days, 3 airports, 40 planes: every `workat` commutes with every other."""
    return read_files(DATA / "maintenance-domain.pddl", DATA / "maintenance-small-problem.pddl")


def _greedy(problem, goal_count: bool = True, commute: bool = False):
    """The greedy phase's rounds (with and without helpful actions) with these lists."""
    variants = (Variant(True, goal_count, commute), Variant(False, goal_count, commute))
    result, expanded = greedy_search(ground(problem), SearchOptions(node_limit=100_000),
                                     NO_SYMMETRIES, None, variants)
    assert result.status is PlanStatus.SOLVED
    return result, expanded


def test_the_goal_count_list_needs_far_fewer_expansions(maintenance) -> None:
    """Counted in expansions: the alternating lists (the default) against FF's lists alone,
    with and without the pruning of commuting orders (the latter is the greedy phase of
    before), on the same task; all three plans are valid."""
    ours, fewer = _greedy(maintenance)
    ff_only, more = _greedy(maintenance, goal_count=False, commute=False)
    before, most = _greedy(maintenance, goal_count=False, commute=True)
    assert fewer * 20 < more and fewer * 20 < most, (fewer, more, most)
    validator = SequentialPlanValidator()
    for result in (ours, ff_only, before):
        up_plan = to_up_plan(maintenance.problem, result.plan)
        assert validator.validate(maintenance.problem, up_plan).status.name == "VALID"


def test_goal_count_is_ignored_when_optimality_counts(maintenance) -> None:
    """h^max at w = 1: the same search with or without the option (no goal-count list)."""
    task = ground(maintenance)
    options = SearchOptions(heuristic="hmax", weight=1.0, node_limit=300)
    plain, asked = search(task, options), search(task, replace(options, goal_count=True))
    assert (plain.status, plain.expanded, plain.generated) == (
        asked.status, asked.expanded, asked.generated)


@pytest.mark.skipif(not native.AVAILABLE, reason="native core not built")
@pytest.mark.parametrize("preferred", [True, False])
@pytest.mark.parametrize("commute", [True, False])
def test_both_engines_alternate_alike(maintenance, make_random, preferred, commute) -> None:
    """The C core's four lists, their turns and boosts are the Python search's: same plan
    and the same expanded/generated counts, on the maintenance task and random ones."""
    tasks = [unit_cost(ground(maintenance))]
    tasks += [ground(make_random(seed, n_fluents=6, n_actions=10)) for seed in range(12)]
    for task in tasks:
        for weight, lazy in ((GREEDY_WEIGHT, True), (2.0, None), (2.0, False)):
            options = SearchOptions(reward=100.0, weight=weight, lazy=lazy, patience=0,
                                    preferred=preferred, goal_count=True, commute=commute,
                                    node_limit=2000)
            py = search(task, replace(options, engine="python"))
            c = search(task, replace(options, engine="native"))
            assert (py.status, [s.label for s in py.plan], py.expanded, py.generated) == (
                c.status, [s.label for s in c.plan], c.expanded, c.generated), options
