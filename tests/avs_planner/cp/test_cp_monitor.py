"""Monitoring, replanning, giving up and virtual-object matching on the corridor problem."""

from __future__ import annotations

from pathlib import Path

import pytest

from avs_planner.cp.continual import ContinualPlanner, Decision
from avs_planner.cp.grounding import ground, world_state
from avs_planner.cp.matching import match_virtual_objects, rename_plan
from avs_planner.cp.monitor import MonitorStatus, monitor
from avs_planner.cp.search import PlanStep, SearchOptions
from avs_planner.pddl import read_text

OPTIONS = SearchOptions(reward=500.0)
AVS = Path(__file__).resolve().parents[3] / "domains" / "avs"


@pytest.fixture(scope="module")
def corridor_text():
    return (AVS / "domain.pddl").read_text(), (AVS / "problems" / "corridor.pddl").read_text()


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


def test_a_confirmed_assumption_is_dropped_instead_of_replanning(corridor_text):
    """The table the plan assumed is found: the match renames it, the assumptions that came
    true leave the plan, and the rest of the plan stands (no needless replan)."""
    domain, problem = corridor_text
    problem = problem.replace("new-object1 new-object2 new-object3 - visualobject",
                              "table1 new-object1 new-object2 new-object3 - visualobject")
    problem = problem.replace("(= (total-cost) 0)", "(= (total-cost) 0) "
                              "(= (p-find-on table table1) 0.8) "
                              "(= (p-find-on cerealbox table1) 0.8)")
    pproblem = read_text(domain, problem, "domain.pddl", "corridor.pddl")
    planner = ContinualPlanner(pproblem, OPTIONS)
    assert planner.replan().solved
    executed = {"(move place0 place1)", "(createviewcones-in table new-room1)",
                "(searchforobject-in table new-room1 new-object1 place1)"}
    assert executed <= {s.label for s in planner.plan}
    planner.plan = tuple(s for s in planner.plan if s.label not in executed)
    seen = {("label-of", "table1", "table"), ("related", "table1", "in", "new-room1")}
    state = planner.state.updated(
        add=[("at", "place1"), ("visited", "place1"), ("viewcones", "table", "in", "new-room1"),
             ("detected", "table1"), ("defined-exists", "table", "in", "new-room1"),
             ("leads-to", "place1", "new-room1"), ("in-room", "place1", "new-room1"),
             ("has-category", "new-room1", "kitchen"), ("defined-leads-to", "place1"),
             ("defined-category", "new-room1"), *seen],
        delete=[("at", "place0"), ("virtual", "new-room1")],
    )
    update = planner.update(state, observed={"table1": seen})
    assert update.decision is Decision.CONTINUE, update.report
    assert update.matched == {"new-object1": "table1"}
    assert set(update.confirmed) == {
        "(assume-leads-to-room place1 kitchen new-room1)",
        "(assume-obj-exists-in table new-room1 kitchen new-object1)",
    }
    labels = [s.label for s in update.plan]
    assert "(createviewcones-on cerealbox table1)" in labels
    assert all("new-object1" not in label for label in labels)
    # without the observation nothing is matched: the table assumption is not confirmed
    # (new-object1 has no label) and the plan still holds with it
    fresh = ContinualPlanner(pproblem, OPTIONS)
    fresh.replan()
    fresh.plan = tuple(s for s in fresh.plan if s.label not in executed)
    kept = fresh.update(state)
    assert "(assume-obj-exists-in table new-room1 kitchen new-object1)" not in kept.confirmed


def test_the_report_gives_each_assumptions_probability_in_the_new_state(planned):
    """What the assumption ledger records after every step (`monitor` trace events)."""
    planner, _ = planned
    leads = next(s.label for s in planner.plan if s.name == "assume-leads-to-room")
    assumed = [s.label for s in planner.plan if s.assumptive]
    moved = planner.state.updated(values={("p-placeholder-category", "place1", "kitchen"): 0.55})
    report = _check(planner, moved)
    assert [label for label, _ in report.assumptions] == assumed
    assert dict(report.assumptions)[leads] == pytest.approx(0.55)
    gone = _check(planner, planner.state.updated(add=[("defined-leads-to", "place1")]))
    assert gone.assumptions == ((leads, 0.0),)  # the first one, contradicted


def test_matching_reads_every_assumption_when_one_is_in_no_task(planned):
    """An assumptive step no task has any more is skipped, and the steps after it are still
    read in every task (the loop once rebound its task list to the step's owner, None here:
    'NoneType' object is not iterable, generated office world 14, book)."""
    planner, _ = planned
    task = ground(planner.pproblem, world_state(planner.pproblem.problem), planner.cache)
    gone = PlanStep("assume-category", ("no-such-room", "kitchen"), 0.0, 0.5, assumptive=True)
    table = {("label-of", "table1", "table"), ("related", "table1", "in", "new-room1")}
    mapping = match_virtual_objects((gone, *planner.plan), [task, task], {"table1": table})
    assert mapping == {"new-object1": "table1"}
