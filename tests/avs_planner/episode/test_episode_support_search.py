"""Support objects in a room (a second desk may exist after the first was found), the DT's
room search skipping known objects, the CP problem skeleton, path reuse while driving, and
rooms of uncertain category visited again (and certain ones doubted) before giving up."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from avs_planner.cp.continual import ContinualPlanner
from avs_planner.cp.search import SearchOptions
from avs_planner.dt import ViewCone
from avs_planner.dt.domain import ActionKind, DTAction
from avs_planner.dt.session import DTResult, DTStatus, DTStep
from avs_planner.episode.driving import TARGET_SEEN, _split_leg
from avs_planner.episode.mind import Mind
from avs_planner.episode.outcome import StepOutcome, StepStatus
from avs_planner.episode.trace import Trace
from avs_planner.episode.viewcones import ConeSet
from avs_planner.harness.sim_robot import Seen
from avs_planner.strategies.switching.loop import LoopConfig

OPTIONS = SearchOptions(weight=3.0, heuristic="hadd", node_limit=4000)


def _here(mind: Mind) -> tuple[str, tuple[float, float]]:
    place = mind.place_map.current_place
    return mind.place_map.room_of(place), mind.place_map.places[place].position


def test_a_found_support_leaves_room_for_another_of_its_label(corridor) -> None:
    mind, builder, _ = corridor
    room, (x, y) = _here(mind)
    table = mind.add_object("table", (x + 0.5, y, 0.4))
    state = builder.build()
    assert ("related", table.id, "in", room) in state.atoms
    # not settled: the CP may still assume (and the DT look for) a second table here
    assert ("defined-exists", "table", "in", room) not in state.atoms
    mind.add_object("cerealbox", (x - 0.5, y, 0.4))
    assert ("defined-exists", "cerealbox", "in", room) in builder.build().atoms


def test_a_room_search_skips_objects_the_mind_knows(corridor) -> None:
    mind, _, executor = corridor
    room, (x, y) = _here(mind)
    mind.add_object("table", (x + 0.5, y, 0.4))
    search = executor.view_cone_search("table", "in", room)
    assert not search._inside(Seen(1, "table", (x + 0.8, y, 0.4), 0.9), "in", room)
    assert search._inside(Seen(2, "table", (x - 1.5, y, 0.4), 0.9), "in", room)


def test_the_skeleton_plans_like_the_full_problem_and_is_shared(corridor) -> None:
    _, builder, _ = corridor
    state = builder.build()
    assert state.skeleton() is builder.build().skeleton()  # same objects, same problem
    full = ContinualPlanner(state.problem(), OPTIONS).replan(state.world_state())
    bare = ContinualPlanner(state.skeleton(), OPTIONS).replan(state.world_state())
    assert full.solved and [s.label for s in full.plan] == [s.label for s in bare.plan]
    assert full.probability == pytest.approx(bare.probability)


def test_split_leg_returns_the_leg_and_the_rest() -> None:
    path = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]
    assert _split_leg(path, 0.5) == ([(0.5, 0.0)], [(0.5, 0.0), (1.0, 0.0), (1.0, 1.0)])
    assert _split_leg(path, 1.5) == ([(1.0, 0.0), (1.0, 0.5)], [(1.0, 0.5), (1.0, 1.0)])
    assert _split_leg(path, 5.0) == ([(1.0, 0.0), (1.0, 1.0)], [(1.0, 1.0)])


def test_a_route_through_a_wall_is_not_clear(corridor) -> None:
    _, _, executor = corridor
    x, y, _ = executor.robot.pose
    assert executor.driver.clear([(x, y), (x + 1.0, y)])
    assert not executor.driver.clear([(x, y), (x, y + 1.5)])  # the office1 wall at y = 4
    assert not executor.driver.clear([(x, y)])


def test_uncertain_rooms_are_found_nearest_first_and_skipped_once_visited(corridor) -> None:
    mind, _, executor = corridor
    room, _ = _here(mind)
    assert executor.uncertain_room(1.01, set()) == room  # every belief is below 1.01
    assert executor.uncertain_room(0.0, set()) is None  # nothing is below 0
    others = executor.uncertain_room(1.01, {room})
    assert others != room
    assert executor.visit_room(room, max_places=2).status is StepStatus.DONE


def test_categories_believed_certain_are_doubted_once_before_giving_up(
        corridor, switching_loop) -> None:
    mind, builder, executor = corridor
    room, _ = _here(mind)
    belief = mind.cmap.room_category(room)
    best = max(belief, key=belief.get)
    # make the current room's reading "certain" for the builder's threshold, as a doorway
    # misreading does, but below the loop's doubt threshold
    builder.config = replace(builder.config, certain_category=belief[best] - 1e-6)
    assert ("has-category", room, best) in builder.build().atoms
    events = []
    trace = Trace(lambda: executor.robot.clock)
    trace.emit = lambda type_, **fields: events.append((type_, fields))  # type: ignore[method-assign]
    loop = switching_loop(builder, executor, trace, LoopConfig(doubt_category=1.0))
    assert loop._doubt_categories()
    assert builder.certain_category == 1.0
    state = builder.build()
    assert ("has-category", room, best) not in state.atoms  # the planner may assume again
    assert any(k[:2] == ("p-room-category", room) for k in state.values)
    assert events and events[0][1]["doubt_categories"] == 1.0
    assert not loop._doubt_categories()  # once per episode


def test_a_search_that_hits_its_node_limit_is_retried_in_the_anytime_mode(
        corridor, switching_loop) -> None:
    """The first CP call stops at its (tiny) expansion limit; the fallback runs the anytime
    schedule (greedy FF first, then weighted A* restarts) and returns a plan."""
    from avs_planner.cp.continual import ContinualPlanner

    _, builder, executor = corridor
    trace = Trace(lambda: executor.robot.clock)
    loop = switching_loop(builder, executor, trace, LoopConfig(cp_node_limit=1))
    state = builder.build()
    loop.planner = ContinualPlanner(state.skeleton(), loop._options(),
                                    min_success=loop.config.min_success)
    first = loop.planner.replan(state.world_state())
    assert first.status.value == "node_limit"
    retried = loop._fallback(first)
    assert retried.solved and "anytime" in retried.extra
    assert loop.planner.options.node_limit == 1  # the loop's own options are restored


def test_the_target_is_looked_at_again_before_it_is_reported(corridor, monkeypatch) -> None:
    """REPORTPOSITION faces the found target and needs one of `verify_frames` frames to see
    it again: a phantom that two frames once agreed on is not reported."""
    import math

    from avs_planner.cp.search import PlanStep

    mind, builder, executor = corridor
    _, (x, y) = _here(mind)
    target = builder.task.target
    obj = mind.add_object(target, (x + 1.0, y + 1.0, 0.5))
    step = PlanStep("reportposition", (obj.id, target), 0.0, 1.0, False)
    frames: list[list[Seen]] = [[], [], []]
    monkeypatch.setattr(executor.robot, "detect",
                        lambda labels=None: frames.pop(0) if frames else [])
    outcome = executor._run(step, builder.build())
    assert outcome.status is StepStatus.FAILED and "not seen again" in outcome.detail
    assert not frames  # all three frames were taken
    yaw = executor.robot.pose[2]
    assert math.isclose(math.cos(yaw - math.atan2(1.0, 1.0)), 1.0, abs_tol=1e-2)
    # the false detection is forgotten: the planner may search its room again
    assert obj.id not in mind.objects and obj.id not in mind.cmap.objects.objects
    assert ("defined-exists", target, "in", obj.room) not in builder.build().atoms
    # ... and kept as a spot to look at once more before the search gives up
    assert mind.unverified == [(target, (x + 1.0, y + 1.0, 0.5))]
    mind.unverified.clear()
    obj = mind.add_object(target, (x + 1.0, y + 1.0, 0.5))
    step = PlanStep("reportposition", (obj.id, target), 0.0, 1.0, False)
    frames[:] = [[], [Seen(7, target, (x + 1.1, y + 1.0, 0.5), 0.8)]]
    assert executor._run(step, builder.build()).status is StepStatus.FOUND
    executor.config = replace(executor.config, verify_frames=0)
    frames[:] = []
    assert executor._run(step, builder.build()).status is StepStatus.FOUND


def _p_in(state, label: str, room: str) -> float:
    return max(v for k, v in state.values.items() if k[:3] == ("p-obj-in", label, room))


@pytest.mark.parametrize("found", [True, False])
def test_a_room_search_thins_the_unseen_count_whether_or_not_it_found_one(corridor,
                                                                           found) -> None:
    """Poisson thinning: the cones looked through leave lambda (1 - coverage p_detect) of
    tables unseen in the room, also after a search that confirmed one (before this, a found
    table left a second one exactly as likely as before the search, and the CP searched the
    same room for tables again and again)."""
    mind, builder, executor = corridor
    room, (x, y) = _here(mind)
    before = _p_in(builder.build(), "table", room)
    left = mind.cmap.objects.remaining(room, "table")  # after the glimpses of the look round
    cones = (ViewCone("c-0", (x, y, 0.0), 0.3), ViewCone("c-1", (x, y, math.pi), 0.3))
    made = ConeSet(cones, coverage=0.8, probability=0.6)
    looked = tuple(DTStep(DTAction(ActionKind.PROCESS_VIEW_CONE, i), None, 1.0, (), 0.0)
                   for i in range(2))
    status = DTStatus.CONFIRMED if found else DTStatus.REJECTED
    seen = Seen(1, "table", (x + 1.0, y, 0.4), 0.9) if found else None
    result = DTResult(status, 0.9, 2.0, looked, detection=seen)
    outcome = executor.view_cone_search("table", "in", room)._conclude(
        result, "table", "in", room, made)
    assert outcome.status is StepStatus.DONE
    assert mind.cmap.objects.remaining(room, "table") == pytest.approx(
        left * (1.0 - 0.8 * (1.0 - executor.config.detector.false_negative)))
    after = _p_in(builder.build(), "table", room)
    assert after < before


def test_a_drive_stops_once_the_watch_confirms_the_target(corridor, monkeypatch) -> None:
    """Driving on to a goal picked to look for the target is wasted once the detector has
    confirmed the target on the way: the drive ends there, and a DT search whose move it was
    ends too (not as a failed search of its location)."""
    mind, builder, executor = corridor
    _, (x, y) = _here(mind)
    target = builder.task.target
    monkeypatch.setattr(executor.robot, "detect", lambda labels=None: [])
    assert executor.drive_to((x + 3.0, y)).detail != TARGET_SEEN  # nothing seen: arrives
    assert math.dist(executor.robot.pose[:2], (x + 3.0, y)) <= executor.config.arrive
    spot = (x + 1.0, y + 0.8, 0.5)
    monkeypatch.setattr(executor.robot, "detect",
                        lambda labels=None: [Seen(9, target, spot, 0.9)]
                        if labels is None or target in labels else [])
    outcome = executor.drive_to((x, y))
    assert outcome.status is StepStatus.DONE and outcome.detail == TARGET_SEEN
    assert math.dist(executor.robot.pose[:2], (x, y)) > executor.config.arrive
    assert [o.label for o in mind.objects.values()] == [target]
    # a DT search whose move to a cone meets the target: it ends, not as a failed search
    room, _ = _here(mind)
    assert executor.create_cones(target, "in", room).status is StepStatus.DONE

    class MovesFirst:  # the DT's first decision: drive to cone 0
        def __init__(self, *args, **kwargs) -> None:
            self.result, self.finished, self.actions = None, False, []

        def next_action(self) -> DTAction:
            if len(self.actions) >= 2:  # (without the early stop: give up after two moves)
                self.update(DTAction(ActionKind.REJECT))
                return DTAction(ActionKind.REJECT)
            return DTAction(ActionKind.MOVE, 0)

        def cone(self, action: DTAction) -> ViewCone:
            return executor.cones_now(target, "in", room).cones[action.cone]

        def update(self, action: DTAction, *args, **kwargs) -> None:
            self.actions.append(action)
            if action.terminal:
                self.finished = True
                self.result = DTResult(DTStatus.REJECTED, 0.5, 0.0, ())

    monkeypatch.setattr("avs_planner.episode.dt_search.DTSession", MovesFirst)
    monkeypatch.setattr(executor.driver, "drive_to",
                        lambda goal, stop=None: StepOutcome(StepStatus.DONE, TARGET_SEEN))
    outcome = executor.view_cone_search(target, "in", room).run()
    assert outcome.status is StepStatus.DONE and outcome.detail == TARGET_SEEN
    assert executor.dt_session.actions == [DTAction(ActionKind.REJECT)]
    assert builder.failed_in.get((target, room), 0) == 0


@pytest.mark.parametrize(("frames", "extra", "confirmed", "taken"), [
    ("hmmh", 2, True, 4),    # one short after three frames, one agreed: two more, one hits
    ("hmmmm", 2, False, 5),  # ... and neither of the two more does
    ("mm", 2, False, 2),     # no frame agreed: rejected as before, no more frames
    ("hmmh", 0, False, 3),   # without the extension: the old two of three
    ("hh", 2, True, 2),
])
def test_a_confirmation_one_short_with_agreement_looks_again(corridor, monkeypatch, frames,
                                                             extra, confirmed, taken) -> None:
    _, builder, executor = corridor
    target = builder.task.target
    x, y, _ = executor.robot.pose
    seen = Seen(1, target, (x + 2.0, y, 0.7), 0.9)
    queue = [[Seen(2, target, (x + 2.1, y, 0.7), 0.9)] if f == "h" else [] for f in frames]
    monkeypatch.setattr(executor.robot, "detect", lambda labels=None: queue.pop(0))
    executor.config = replace(executor.config, confirm_extra=extra)
    assert executor.confirm(seen) is confirmed
    assert len(frames) - len(queue) == taken


def test_the_success_threshold_bounds_the_search_not_its_result(corridor, switching_loop) -> None:
    """The CP is asked for the best plan among those with p >= min_success: filtered after the
    search, a cheap hopeless best plan (p 0.008) hid a worthwhile one (p 0.07) and the robot
    gave up 27 s in (generated office 3, stapler)."""
    from avs_planner.cp.continual import ContinualPlanner

    _, builder, executor = corridor
    loop = switching_loop(builder, executor, Trace(lambda: executor.robot.clock),
                         LoopConfig(min_success=0.2))
    assert loop._options().min_success == 0.2
    state = builder.build()
    planner = ContinualPlanner(state.skeleton(), loop._options(), min_success=0.2)
    result = planner.replan(state.world_state())
    assert not result.solved or result.probability >= 0.2


def test_a_spot_the_verification_missed_is_looked_at_once_more(corridor, monkeypatch) -> None:
    """No plan is good enough: the loop looks once more at a spot where frames had confirmed
    the target before the verification missed it (`Recovery.recheck_unverified`); seen
    again, it is a known object for the planner to report. Each spot once; spots of other
    labels are not the target's."""
    from avs_planner.strategies.switching.loop import LoopConfig
    from avs_planner.strategies.switching.recovery import Recovery

    mind, builder, executor = corridor
    _, (x, y) = _here(mind)
    target = builder.task.target
    spot = (x + 1.0, y + 0.5, 0.5)
    trace = Trace(lambda: executor.robot.clock, None, None)
    recovery = Recovery(builder, executor, trace, LoopConfig())
    assert not recovery.recheck_unverified()  # nothing to look at again
    mind.unverified.append(("stapler", spot))
    assert not recovery.recheck_unverified() and mind.unverified == [("stapler", spot)]
    mind.unverified.append((target, spot))
    monkeypatch.setattr(executor.robot, "detect",
                        lambda labels=None: [Seen(9, target, spot, 0.9)]
                        if labels is None or target in labels else [])
    assert recovery.recheck_unverified()
    assert mind.unverified == [("stapler", spot)]  # the target's spot is used up
    again = [o for o in mind.objects.values() if o.label == target]
    assert len(again) == 1 and again[0].position == spot
    events = [e for e in trace.events if e.get("action") == f"(look-again {target})"]
    assert [e["status"] for e in events] == ["start", "done"]
    assert events[1]["detail"] == f"seen again: {again[0].id}"
    assert not recovery.recheck_unverified()  # once per spot
