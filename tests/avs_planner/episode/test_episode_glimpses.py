"""Frames taken in passing as evidence (glimpses), the planner's own objective as a stopping
rule, and a re-decision after every search the DT rejected."""

from __future__ import annotations

import math

import numpy as np
import pytest

from avs_planner.cp.search import PlanResult, PlanStatus, PlanStep
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.outcome import StepOutcome, StepStatus
from avs_planner.episode.trace import Trace
from avs_planner.strategies.switching.loop import LoopConfig, _explores, _search_rejected
from conceptual_map.conceptual import ConceptualError, RelatedSpace
from conceptual_map.conceptual.existence import ObjectLedger
from conceptual_map.knowledge import load_knowledge

# ---- the ledger: glimpses are one more look, replaced (not multiplied) by the next share ----

def test_glimpses_replace_the_last_share_and_multiply_with_searches() -> None:
    ledger = ObjectLedger(load_knowledge())
    ledger.record_search("cup", "r1", coverage=0.5, p_detect=0.8)  # DT search: 0.6 left
    ledger.record_glimpses("cup", "r1", 0.3)
    assert ledger.remaining("r1", "cup") == pytest.approx(0.6 * 0.7)
    ledger.record_glimpses("cup", "r1", 0.5)  # the frames' latest share, not 0.7 x 0.5
    assert ledger.remaining("r1", "cup") == pytest.approx(0.6 * 0.5)
    assert ledger.remaining("r2", "cup") == 1.0


def test_merged_rooms_keep_the_smaller_glimpsed_share() -> None:
    ledger = ObjectLedger(load_knowledge())
    ledger.record_glimpses("cup", "gone", 0.8)
    ledger.record_glimpses("cup", "keep", 0.4)
    ledger.record_glimpses("book", "gone", 0.9)  # "keep" never glimpsed for books: 0
    ledger.move_room("gone", "keep")
    assert ledger.remaining("keep", "cup") == pytest.approx(0.6)
    assert ledger.remaining("keep", "book") == 1.0
    assert ledger.remaining("gone", "cup") == 1.0
    ledger.forget_room("keep")
    assert ledger.remaining("keep", "cup") == 1.0


@pytest.mark.parametrize("share", [-0.1, 1.5, "most", True])
def test_a_bad_glimpsed_share_is_a_clear_error(share) -> None:
    with pytest.raises(ConceptualError, match="share must be a number in"):
        ObjectLedger(load_knowledge()).record_glimpses("cup", "r1", share)


# ---- frames in passing: what is in view, with a free line of sight, once per standpoint -----

def _glimpses(mind, executor) -> Glimpses:
    return Glimpses(mind, executor.camera, p_detect=0.64)


def _room_and_pose(mind):
    place = mind.place_map.current_place
    return mind.place_map.room_of(place), mind.place_map.places[place].position


def test_a_frame_lowers_the_target_where_it_looked_once_per_standpoint(corridor) -> None:
    mind, _, executor = corridor
    room, (x, y) = _room_and_pose(mind)
    g = _glimpses(mind, executor)
    best = None
    for k in range(8):  # the heading that sees most of this room's candidate cells
        changed = _glimpses(mind, executor).frame((x, y, k * math.pi / 4), 0.0, -0.2,
                                                  ["cerealbox"])
        share = changed.get("cerealbox", {}).get(room, 0.0)
        if best is None or share > best[1]:
            best = (k * math.pi / 4, share)
    assert best is not None and best[1] > 0.0, "no heading saw any of the room"
    mind.cmap.objects._glimpsed.clear()  # the loop above wrote shares too
    changed = g.frame((x, y, best[0]), 0.0, -0.2, ["cerealbox"])
    share = changed["cerealbox"][room]
    assert mind.cmap.objects.remaining(room, "cerealbox") == pytest.approx(1.0 - share,
                                                                        abs=1e-3)
    # the same view again adds nothing (a second frame from one standpoint is not a second
    # chance); a new standpoint's frame is one more look at the cells it shares
    assert g.frame((x, y, best[0]), 0.0, -0.2, ["cerealbox"]) == {}
    g.frame((x - 1.5 * math.cos(best[0]), y - 1.5 * math.sin(best[0]), best[0]), 0.0, -0.2,
            ["cerealbox"])
    assert mind.cmap.objects.remaining(room, "cerealbox") < 1.0 - share - 1e-3
    # an object the frame did not look for is not evidence
    assert mind.cmap.objects.remaining(room, "table") == 1.0


def test_a_frame_that_shows_one_desk_shows_no_other_where_it_looked(corridor) -> None:
    """A frame that shows a desk did not show a second one anywhere else in view: the cells
    it had in view count as looked at for desks, except near the desk it showed (there, a
    second detection would be the same desk)."""
    mind, _, executor = corridor
    room, (x, y) = _room_and_pose(mind)
    heading, most = 0.0, 0
    for k in range(8):  # the heading that sees most of this room's candidate cells
        g = _glimpses(mind, executor)
        g.frame((x, y, k * math.pi / 4), 0.0, -0.2, ["cerealbox"])
        if len(g.cells.get("cerealbox", {})) > most:
            heading, most = k * math.pi / 4, len(g.cells["cerealbox"])
    seen = {key for key in _glimpses_cells(mind, executor, (x, y, heading))}
    assert seen, "no heading saw any of the room"
    res = mind.grid.resolution
    desk = np.array(sorted(seen)[len(seen) // 2]) * res  # a cell the frame had in view
    mind.cmap.objects._glimpsed.clear()
    g = _glimpses(mind, executor)
    changed = g.frame((x, y, heading), 0.0, -0.2, [], shown={"desk": [tuple(desk)]})
    looked = set(g.cells["desk"])
    assert changed["desk"][room] > 0.0
    assert mind.cmap.objects.remaining(room, "desk") < 1.0
    def near(key: tuple[int, int], slack: float) -> bool:  # keys are cells rounded
        return math.dist(np.array(key) * res, desk) <= g.support_body + slack

    assert looked < seen
    assert not any(near(key, -res) for key in looked)
    assert all(near(key, res) for key in seen - looked)
    # a label the frame did not show is looked for everywhere in view; one listed as not
    # shown is not also taken as shown
    g = _glimpses(mind, executor)
    g.frame((x, y, heading), 0.0, -0.2, ["desk"], shown={"desk": [tuple(desk)]})
    assert set(g.cells["desk"]) == seen


def _glimpses_cells(mind, executor, pose) -> set:  # noqa: ANN001
    g = _glimpses(mind, executor)
    g.frame(pose, 0.0, -0.2, ["cerealbox"])
    mind.cmap.objects._glimpsed.clear()
    return set(g.cells["cerealbox"])


def test_a_frame_does_not_see_through_walls(corridor) -> None:
    mind, _, executor = corridor
    g = _glimpses(mind, executor)
    grid = mind.grid
    occupied = grid.to_world(np.argwhere(grid.state_grid() == 2))  # CellState.OCCUPIED
    assert len(occupied), "the corridor's walls are mapped"
    x, y = mind.place_map.places[mind.place_map.current_place].position
    wall = occupied[np.hypot(*(occupied - [x, y]).T).argmin()]  # the nearest wall cell
    beyond = wall + 1.0 * (wall - np.array([x, y])) / np.linalg.norm(wall - np.array([x, y]))
    clear = g.line_of_sight(np.array([x, y]), np.array([wall, beyond]))
    assert clear[0] and not clear[1]  # the wall cell itself is seen; behind it is not


def test_a_support_top_seen_from_two_standpoints_is_two_looks(corridor) -> None:
    mind, _, executor = corridor
    room, (x, y) = _room_and_pose(mind)
    table = mind.add_object("table", (x + 2.0, y, 0.375))
    g = _glimpses(mind, executor)
    where = RelatedSpace("on", table.id)
    g.frame((x, y, 0.0), 0.0, -0.15, [], [table.id], tops_label="cerealbox")
    once = mind.cmap.objects.remaining(where, "cerealbox")
    assert once == pytest.approx(0.36)
    g.frame((x + 0.1, y, 0.0), 0.0, -0.15, [], [table.id], tops_label="cerealbox")
    assert mind.cmap.objects.remaining(where, "cerealbox") == pytest.approx(once)
    g.frame((x + 3.5, y + 0.5, math.atan2(-0.5, -1.5)), 0.0, -0.15, [], [table.id],
            tops_label="cerealbox")  # from the far side, 1.6 m away: part of the top in view
    twice = mind.cmap.objects.remaining(where, "cerealbox")
    assert 0.36 ** 2 < twice < once  # the part seen twice is down to 0.36^2, the rest 0.36
    seen = g.tops[("cerealbox", table.id)]
    twice_seen = sum(len(stands) == 2 for stands in seen) / len(seen)
    assert twice == pytest.approx(twice_seen * 0.36 ** 2 + (1 - twice_seen) * 0.36)


def test_the_frames_before_a_support_was_known_count_for_its_top(corridor) -> None:
    """The frames that found a table (before it was a known object) had its top in view
    without the target on it: once the table is known, they count as looks at its top.
    Counted only from then on, a desk found in the first look round kept its whole prior
    share, and the CP planned a search of it as if nobody had looked."""
    mind, _, executor = corridor
    room, (x, y) = _room_and_pose(mind)
    g = _glimpses(mind, executor)
    # a frame that did not show the target (it is among the labels the frame did not show),
    # with no support known yet
    g.frame((x, y, 0.0), 0.0, -0.15, ["cerealbox"], [], tops_label="cerealbox")
    table = mind.add_object("table", (x + 2.0, y, 0.375))
    where = RelatedSpace("on", table.id)
    assert mind.cmap.objects.remaining(where, "cerealbox") == pytest.approx(1.0)
    # the next frame looks away from the table; the first one is credited to its top now
    g.frame((x, y, math.pi), 0.0, -0.15, ["cerealbox"], [table.id], tops_label="cerealbox")
    assert mind.cmap.objects.remaining(where, "cerealbox") == pytest.approx(0.36)
    # once only
    g.frame((x, y, math.pi), 0.0, -0.15, ["cerealbox"], [table.id], tops_label="cerealbox")
    assert mind.cmap.objects.remaining(where, "cerealbox") == pytest.approx(0.36)


def test_a_frame_that_showed_the_target_is_not_counted_for_a_support_later(corridor) -> None:
    mind, _, executor = corridor
    room, (x, y) = _room_and_pose(mind)
    g = _glimpses(mind, executor)
    # the target was in this frame: it is not among the labels the frame did not show
    g.frame((x, y, 0.0), 0.0, -0.15, ["table"], [], tops_label="cerealbox")
    table = mind.add_object("table", (x + 2.0, y, 0.375))
    g.frame((x, y, math.pi), 0.0, -0.15, ["cerealbox"], [table.id], tops_label="cerealbox")
    assert mind.cmap.objects.remaining(RelatedSpace("on", table.id), "cerealbox") == \
        pytest.approx(1.0)


# ---- the CP's objective as a stopping rule -------------------------------------------------

def _result(steps: list[PlanStep], p: float, cost: float) -> PlanResult:
    return PlanResult(PlanStatus.SOLVED, tuple(steps), cost=cost, probability=p)


LOCAL = [PlanStep("move", ("place1", "place2"), 5.0, 1.0),
         PlanStep("searchforobject-in", ("cerealbox", "room1", "new-object1", "place2"),
                  120.0, 0.5)]
EXPLORING = [PlanStep("move", ("place1", "placeholder3"), 5.0, 1.0), *LOCAL[1:]]


def test_a_plan_worth_less_than_it_costs_is_not_executed(corridor, switching_loop) -> None:
    _, builder, executor = corridor
    events = []
    trace = Trace(lambda: executor.robot.clock)
    trace.emit = lambda type_, **fields: events.append((type_, fields))  # type: ignore
    loop = switching_loop(builder, executor, trace, LoopConfig(reward=500.0))
    judged = loop._worth_it(_result(LOCAL, p=0.2, cost=125.0))  # 500 x 0.2 = 100 < 125
    assert judged.status is PlanStatus.NO_PLAN_ABOVE_THRESHOLD and not judged.plan
    assert "worth" in loop._no_plan(judged) and "p=0.2" in loop._no_plan(judged)
    assert events and events[-1][1]["not_worth"]
    assert loop._worth_it(_result(LOCAL, p=0.3, cost=125.0)).solved  # 150 > 125
    # a plan that explores is kept: exploring shows more than its one chain of assumptions
    assert loop._worth_it(_result(EXPLORING, p=0.05, cost=125.0)).solved
    off = switching_loop(builder, executor, trace, LoopConfig(worth_test=False))
    assert off._worth_it(_result(LOCAL, p=0.2, cost=125.0)).solved


def test_what_counts_as_exploring_and_as_a_rejected_search() -> None:
    assert _explores(tuple(EXPLORING)) and not _explores(tuple(LOCAL))
    assume = PlanStep("assume-leads-to-room", ("placeholder2", "kitchen", "new-room1"), 0, 0.3,
                      assumptive=True)
    assert _explores((assume,))
    search = LOCAL[1]
    assert _search_rejected(search, StepOutcome(StepStatus.DONE, "rejected"))
    assert not _search_rejected(search, StepOutcome(StepStatus.DONE, "confirmed object3"))
    assert not _search_rejected(LOCAL[0], StepOutcome(StepStatus.DONE, "rejected"))


def test_a_path_query_refused_where_the_robot_stands_is_no_path_not_a_crash(
        corridor, monkeypatch) -> None:
    from conceptual_map.metric.errors import PathQueryError

    _, _, executor = corridor

    def refuse(*args, **kwargs):
        raise PathQueryError("goal is blocked: closer than the robot radius")

    monkeypatch.setattr("avs_planner.episode.driving.plan_path", refuse)
    path = executor.driver.squeeze((6.0, 3.2), (8.0, 3.2))
    assert not path.found


def test_searches_priced_in_the_robots_seconds_learn_from_timed_searches(corridor) -> None:
    from dataclasses import replace

    mind, builder, executor = corridor
    seed_cost = builder.search_cost("cerealbox", "in")
    # off: the active visual search paper's numbers
    assert seed_cost == builder.config.target_search_cost[0]
    mind.body = executor.robot.body()
    builder.config = replace(builder.config, seconds=True)
    body = mind.body
    per_cone = 2.0 / body.linear_speed + body.turn_time(math.pi / 2) + 2 * body.sensing_time
    prior = builder.search_cost("cerealbox", "in")
    assert prior == pytest.approx(6 * per_cone, abs=1e-3)
    builder.observe_search_time("cerealbox", "in", 30.0)
    assert builder.search_cost("cerealbox", "in") == pytest.approx((prior + 30.0) / 2, abs=1e-3)
    assert builder.search_cost("table", "in") != builder.search_cost("cerealbox", "in")
    state = builder.build()
    assert state.values[("search-cost", "cerealbox", "in")] == pytest.approx(
        (prior + 30.0) / 2, abs=1e-3)
    moves = [v for k, v in state.values.items() if k[0] == "move-cost" and v > 0]
    builder.config = replace(builder.config, seconds=False)
    metres = [v for k, v in builder.build().values.items() if k[0] == "move-cost" and v > 0]
    assert moves and sorted(moves) == pytest.approx(
        sorted(m / body.linear_speed for m in metres), abs=1e-2)


def test_a_placeholder_on_space_seen_but_not_visited_is_a_goal(corridor) -> None:
    """Unvisited free space (a room looked into through its door) gets a placeholder with no
    frontier (length 0): the planner must still be offered it."""
    from dataclasses import replace

    mind, builder, _ = corridor
    pm = mind.place_map
    before = builder.build().objects.get("placeholder", [])
    assert before, "the corridor's look round leaves placeholders"
    pid = before[0]
    for other in pm.placeholders:  # the others were given up on: only this one is left
        if other != pid:
            mind.tried_placeholders[other] = builder.config.max_placeholder_tries
    pm.placeholders[pid] = replace(pm.placeholders[pid], frontier_length=0.0)
    assert builder.build().objects.get("placeholder", []) == [pid]


def test_a_search_the_robot_cannot_stand_for_is_settled_not_offered_again(corridor) -> None:
    """No view cone for a support (none this body can stand at): the search fails, and the
    location is settled, so the same search is not offered again from the same state (the
    loop would give up: 'failed from this very state before')."""
    mind, builder, executor = corridor
    _, (x, y) = _room_and_pose(mind)
    table = mind.add_object("table", (x + 1.0, y, 0.375))
    assert ("defined-exists", "cerealbox", "on", table.id) not in builder.build().atoms
    outcome = executor.search("cerealbox", "on", table.id)  # no CREATEVIEWCONES was run
    assert outcome.status is StepStatus.FAILED
    assert ("defined-exists", "cerealbox", "on", table.id) in builder.build().atoms
