"""Monitoring, replanning, giving up and virtual-object matching on the corridor problem."""

from __future__ import annotations

import pytest

from avs_planner.cp.continual import ContinualPlanner, Decision
from avs_planner.cp.grounding import ground, world_state
from avs_planner.cp.matching import match_virtual_objects, rename_plan
from avs_planner.cp.monitor import MonitorStatus, monitor
from avs_planner.cp.search import SearchOptions

OPTIONS = SearchOptions(reward=500.0)


@pytest.fixture(scope="module")
def planned(corridor):
    planner = ContinualPlanner(corridor, OPTIONS)
    result = planner.replan()
    assert result.solved
    return planner, result


def _check(planner, state):
    return monitor(planner.plan, ground(planner.pproblem, state, planner.cache))


def test_fresh_plan_is_valid(planned):
    planner, result = planned
    report = _check(planner, planner.state)
    assert report.status is MonitorStatus.VALID
    assert report.probability == pytest.approx(result.probability)


def test_precondition_failure_names_the_step_and_atom(planned):
    planner, _ = planned
    state = planner.state.updated(add=[("at", "place2")], delete=[("at", "place0")])
    report = _check(planner, state)
    assert report.status is MonitorStatus.PRECONDITION_FAILED
    assert report.action == "(move place0 place1)"
    assert "(at place0)" in report.failed


def test_contradicted_assumption(planned):
    planner, _ = planned
    # exploring place1 fixed what it leads to: the kitchen assumption can no longer be made
    state = planner.state.updated(add=[("defined-leads-to", "place1")])
    report = _check(planner, state)
    assert report.status is MonitorStatus.ASSUMPTION_CONTRADICTED
    assert report.step == 0


def test_assumption_probability_dropping_to_zero_contradicts_it(planned):
    planner, _ = planned
    state = planner.state.updated(values={("p-placeholder-category", "place1", "kitchen"): 0.0})
    assert _check(planner, state).status is MonitorStatus.ASSUMPTION_CONTRADICTED


def test_probability_change_beyond_threshold(planned):
    planner, _ = planned
    small = planner.state.updated(values={("p-placeholder-category", "place1", "kitchen"): 0.55})
    assert _check(planner, small).status is MonitorStatus.VALID
    big = planner.state.updated(values={("p-placeholder-category", "place1", "kitchen"): 0.3})
    report = _check(planner, big)
    assert report.status is MonitorStatus.PROBABILITY_CHANGED
    assert "assumption" in report.detail


def test_goal_no_longer_reached(planned):
    planner, _ = planned
    task = ground(planner.pproblem, planner.state, planner.cache)
    report = monitor(planner.plan[:-1], task)
    assert report.status is MonitorStatus.GOAL_NOT_REACHED


def test_update_continues_replans_and_gives_up(corridor):
    planner = ContinualPlanner(corridor, OPTIONS)
    first = planner.replan()
    kept = planner.update(planner.state)
    assert kept.decision is Decision.CONTINUE
    assert kept.plan == first.plan
    contradicted = planner.state.updated(add=[("defined-leads-to", "place1")])
    replanned = planner.update(contradicted)
    assert replanned.decision is Decision.REPLANNED
    assert replanned.report.status is MonitorStatus.ASSUMPTION_CONTRADICTED
    assert all("place1 kitchen" not in s.label for s in replanned.plan)
    assert replanned.result.probability < first.probability
    strict = ContinualPlanner(corridor, OPTIONS, min_success=0.5)
    assert strict.update(strict.state).decision is Decision.GIVE_UP


def test_matching_a_detected_table_to_the_virtual_object(planned):
    planner, _ = planned
    task = ground(planner.pproblem, world_state(planner.pproblem.problem), planner.cache)
    table = {("label-of", "table1", "table"), ("related", "table1", "in", "new-room1")}
    box = {("label-of", "box", "cerealbox"), ("related", "box", "in", "new-room1")}
    mapping = match_virtual_objects(planner.plan, task, {"table1": table, "box": box})
    assert mapping == {"new-object1": "table1"}
    renamed = rename_plan(planner.plan, mapping)
    assert "(searchforobject-in table new-room1 table1 place1)" in [s.label for s in renamed]


def test_no_match_when_the_observation_contradicts_the_description(planned):
    planner, _ = planned
    task = ground(planner.pproblem, planner.state, planner.cache)
    elsewhere = {("label-of", "table2", "table"), ("related", "table2", "in", "room1")}
    assert match_virtual_objects(planner.plan, task, {"table2": elsewhere}) == {}
