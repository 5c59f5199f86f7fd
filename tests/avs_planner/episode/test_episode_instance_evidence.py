"""Evidence about one support instance reaches the planner and the DT: a desk searched once is
not planned, nor searched, as if it never had been; every look of a DT search counts; and a
new place is looked at all round."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import replace
from types import SimpleNamespace

import pytest

from avs_planner.dt import ViewCone
from avs_planner.dt.domain import ActionKind, DTAction
from avs_planner.dt.session import DTResult, DTStatus, DTStep
from avs_planner.episode.dt_search import looked_share
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.mind import Mind
from avs_planner.episode.viewcones import CameraModel, ConeSet, room_cones, support_cones
from conceptual_map.conceptual import RelatedSpace
from conceptual_map.metric import CellState
from conceptual_map.metric.synthetic import rooms_world


def _here(mind):
    place = mind.place_map.current_place
    return mind.place_map.room_of(place), mind.place_map.places[place].position


def _looks(*cones: int) -> tuple[DTStep, ...]:
    return tuple(DTStep(DTAction(ActionKind.PROCESS_VIEW_CONE, i), None, 1.0, (), 0.0)
                 for i in cones)


def test_every_look_of_a_dt_search_into_a_cone_counts(corridor) -> None:
    """Two looks into one cone are two chances for the detector: that cone's share of the
    location is left unseen with (1 - p_detect)^2, not (1 - p_detect)."""
    mind, _, executor = corridor
    room, (x, y) = _here(mind)
    left = mind.cmap.objects.remaining(room, "table")
    cones = (ViewCone("c-0", (x, y, 0.0), 0.3), ViewCone("c-1", (x, y, math.pi), 0.3))
    made = ConeSet(cones, coverage=0.8, probability=0.6)
    result = DTResult(DTStatus.REJECTED, 0.05, 2.0, _looks(0, 0, 1))
    executor.view_cone_search("table", "in", room)._conclude(result, "table", "in", room, made)
    d = 1.0 - executor.config.detector.false_negative
    seen = 0.8 * (0.5 * (1.0 - (1.0 - d) ** 2) + 0.5 * d)
    assert mind.cmap.objects.remaining(room, "table") == pytest.approx(left * (1.0 - seen))


def test_a_room_search_thins_by_its_coverage_once(corridor) -> None:
    """A room's cones carry P(ObjectAt) x their share of its cells, adding up to P x
    coverage: looking once into each of them leaves 1 - p_detect x coverage of the room's
    count unseen (it used to leave 1 - p_detect x coverage^2, the coverage counted twice)."""
    mind, _, executor = corridor
    room, _ = _here(mind)
    made = room_cones(mind, room, "table", 0.5, executor.camera, "k")
    assert made.cones and 0.0 < made.coverage < 1.0
    assert sum(c.probability for c in made.cones) == pytest.approx(0.5 * made.coverage)
    left = mind.cmap.objects.remaining(room, "table")
    result = DTResult(DTStatus.REJECTED, 0.05, 2.0, _looks(*range(len(made.cones))))
    executor.view_cone_search("table", "in", room)._conclude(result, "table", "in", room, made)
    d = 1.0 - executor.config.detector.false_negative
    assert mind.cmap.objects.remaining(room, "table") == pytest.approx(
        left * (1.0 - d * made.coverage))


def test_a_support_search_counts_each_standpoint_as_a_look_at_the_whole_top(corridor) -> None:
    """The cones round a support each see most of its top: a search that looks through all
    of them has had several chances at an object anywhere on it (as frames in passing
    count, `Glimpses.top_share`), not one chance at each cone's fraction of it, which left
    1 - 0.9 p_detect of a desk unsearched however many cones looked at it."""
    mind, _, executor = corridor
    executor.enable_glimpses()
    room, (x, y) = _here(mind)
    table = mind.add_object("table", (x + 2.0, y, 0.375))
    made = support_cones(mind, table, 0.5, executor.camera, "k")
    assert len(made.cones) >= 2
    looks = {i: 1 for i in range(len(made.cones))}
    d = 1.0 - executor.config.detector.false_negative
    result = DTResult(DTStatus.REJECTED, 0.05, 2.0, _looks(*looks))
    executor.view_cone_search("cerealbox", "on", table.id)._conclude(
        result, "cerealbox", "on", table.id, made)
    share = executor.glimpses.top_share(
        table.id, [(c.pose, *c.head, 1) for c in made.cones])
    left = mind.cmap.objects.remaining(RelatedSpace("on", table.id), "cerealbox")
    assert left == pytest.approx(1.0 - share)
    assert share > looked_share(made, looks, d)
    # one look from one side is one chance at the part of the top it had in view; from the
    # other side, a second chance where the two views overlap and a first one elsewhere
    first, last = ((c.pose, *c.head, 1) for c in (made.cones[0], made.cones[-1]))
    one = executor.glimpses.top_share(table.id, [first])
    assert 0.0 < one < d
    assert one < executor.glimpses.top_share(table.id, [first, last]) <= share


def _support(mind, builder):
    room, (x, y) = _here(mind)
    table = mind.add_object("table", (x + 2.0, y, 0.375))
    return table, RelatedSpace("on", table.id)


def test_a_searched_support_is_planned_with_what_is_left_on_it(corridor) -> None:
    """`p-find-on` is the detection rate on a support untouched by looks, and that rate times
    P(on it now) / P(on it before any look) after a search of it: the CP's second search of
    the same desk is worth what the first left, not the prior again."""
    mind, builder, _ = corridor
    table, where = _support(mind, builder)
    state = builder.build()
    rate = state.values[("p-detect", "cerealbox", "on")]
    assert state.values[("p-find-on", "cerealbox", table.id)] == pytest.approx(rate)
    assert state.values[("p-find-on", "cerealbox", "new-object1")] == pytest.approx(rate)
    before = mind.cmap.p_object_at("cerealbox", where, include_sublocations=False)
    mind.searched("cerealbox", "on", table.id, coverage=0.9, p_detect=0.64)
    after = mind.cmap.p_object_at("cerealbox", where, include_sublocations=False)
    assert 0.0 < after < before
    # over the prior under the room's category belief and the building's cereal-box rate
    # now (the failed search moved both)
    lam = mind.cmap.knowledge.relation_lambda_of("cerealbox", "on", "table")
    prior = float(mind.cmap.room_marginal(table.room) @ mind.cmap.p_any("cerealbox", lam))
    found = builder.build().values[("p-find-on", "cerealbox", table.id)]
    assert found == pytest.approx(rate * after / prior, rel=1e-3)
    assert found < rate
    # the problem as PDDL carries it, and the domain's search on a support reads it
    text = builder.build().to_pddl()
    match = re.search(rf"\(= \(p-find-on cerealbox {table.id}\) ([0-9.]+)\)", text)
    assert match is not None and float(match.group(1)) == pytest.approx(found, abs=1e-6)
    problem = builder.build().problem()
    assert "p-find-on" in str(problem.success["searchforobject-on"])


def test_a_second_dt_search_starts_from_what_the_first_left(corridor) -> None:
    """The cones made for a location keep their shape; a later search scales their
    probabilities by the map's P(ObjectAt) now over when they were made."""
    mind, builder, executor = corridor
    table, where = _support(mind, builder)
    (x, y) = table.position[:2]
    cones = (ViewCone("c-0", (x - 1.0, y, 0.0), 0.2), ViewCone("c-1", (x + 1.0, y, math.pi), 0.2))
    key = ("cerealbox", "on", table.id)
    executor.cones[key] = ConeSet(cones, coverage=0.9, probability=0.4)
    executor.cone_basis[key] = executor.location_belief(*key)
    assert executor.cones_now(*key) is executor.cones[key]
    before = executor.cone_basis[key]
    mind.searched("cerealbox", "on", table.id, coverage=0.9, p_detect=0.64)
    scale = executor.location_belief(*key) / before
    now = executor.cones_now(*key)
    assert 0.0 < scale < 1.0
    assert now.probability == pytest.approx(0.4 * scale)
    assert [c.probability for c in now.cones] == pytest.approx([0.2 * scale] * 2)
    assert [c.pose for c in now.cones] == [c.pose for c in cones]


@pytest.mark.parametrize("headings", [2, 6])
def test_a_new_place_is_looked_at_in_every_direction(corridor, headings) -> None:
    """`look_headings` spreads the detector's frames evenly over a full turn."""
    _, _, executor = corridor
    executor.config = replace(executor.config, look_headings=headings)
    yaws: list[float] = []
    executor.sensing.watch = lambda: yaws.append(executor.robot.pose[2])  # type: ignore[method-assign]
    start = executor.robot.pose[2]
    executor.look_around()
    assert len(yaws) == headings
    offsets = sorted(round(((y - start) % (2 * math.pi)) / (2 * math.pi / headings)) % headings
                     for y in yaws)
    assert offsets == list(range(headings))


# ---- a support's top is seen over its own body, not through a wall -------------------------

def _box_room(desk: tuple[float, float, float, float], wall_x: float | None = None):
    """A 8 x 5 m room with a desk-sized box (seen by the laser as its outline, unknown
    inside), optionally a wall across the room at x = `wall_x` with a door at its end."""
    world = rooms_world([(0.0, 0.0, 8.0, 5.0)], [], wall=0.1)
    world.add_box(*desk, 0.0, 0.75)
    if wall_x is not None:
        world.add_box(wall_x - 0.05, 0.0, wall_x + 0.05, 4.0, 0.0, 2.0)
    mind = Mind()
    for pose in [(1.0, 2.5, 0.0), (1.0, 2.5, math.pi)]:
        mind.sense(world.laser(pose, beams=1440, fov=4.18, max_range=5.6), [pose], 0.0)
    return mind


def _top_seen(mind, desk_centre, body: float = 0.9) -> bool:
    glimpses = Glimpses(mind, CameraModel(1.2, math.radians(60), 4.0), p_detect=0.64,
                        support_body=body)
    table = mind.add_object("table", (*desk_centre, 0.375))
    glimpses.frame((1.0, 2.5, 0.0), 0.0, -0.2, [], [table.id], tops_label="cerealbox")
    return mind.cmap.objects.remaining(RelatedSpace("on", table.id), "cerealbox") < 1.0


def test_a_support_top_is_seen_over_its_own_body() -> None:
    """The laser maps a desk as its outline with unknown cells inside: a ray to its centre
    crosses them, and that must not hide the top (before, no top in view ever counted)."""
    mind = _box_room((3.0, 2.0, 4.2, 3.0))
    assert mind.grid.state_grid()[mind.grid.cell_of((3.6, 2.5))] != CellState.FREE
    assert not _top_seen(_box_room((3.0, 2.0, 4.2, 3.0)), (3.6, 2.5), body=0.0)
    assert _top_seen(mind, (3.6, 2.5))


def test_a_support_top_behind_a_wall_is_not_seen() -> None:
    mind = _box_room((3.0, 2.0, 4.2, 3.0), wall_x=2.5)
    assert not _top_seen(mind, (3.6, 2.5))


def test_a_room_searched_through_is_not_worth_reading_again(corridor) -> None:
    """`could_hold`: under its most favourable category, the target's unseen probability in
    the room (its known supports included) against the planner's threshold."""
    mind, builder, _ = corridor
    room, _ = _here(mind)
    table = mind.add_object("table", (*_here(mind)[1], 0.375))
    assert builder.could_hold(room)
    mind.searched("cerealbox", "in", room, coverage=1.0, p_detect=0.99)
    assert builder.could_hold(room)  # still possible on the table
    mind.searched("cerealbox", "on", table.id, coverage=1.0, p_detect=0.99)
    assert not builder.could_hold(room)
    assert not builder.could_hold("no-such-room")


def test_a_top_partly_in_the_frame_is_searched_in_part() -> None:
    """The centre in view is not enough to rule the whole top out: an object at the desk's
    end (anywhere within `support_body` of its centre) may be outside the frame, so only the
    points of the top inside it count (the mean over them, as for a room's cells), or the
    desk would be settled by frames that never had its far end in view."""
    mind = _box_room((3.0, 2.0, 4.2, 3.0))
    glimpses = Glimpses(mind, CameraModel(1.2, math.radians(60), 4.0), p_detect=0.64)
    table = mind.add_object("table", (3.6, 2.5, 0.375))
    where = RelatedSpace("on", table.id)
    turned = math.radians(20)  # the centre 20 deg off the axis: inside the 30 deg half-view
    glimpses.frame((1.0, 2.5, turned), 0.0, -0.2, [], [table.id], tops_label="cerealbox")
    part = mind.cmap.objects.remaining(where, "cerealbox")
    assert 0.36 < part < 1.0
    for _ in range(3):  # the same frame again: the same standpoint, no new look
        glimpses.frame((1.0, 2.5, turned), 0.0, -0.2, [], [table.id], tops_label="cerealbox")
    assert mind.cmap.objects.remaining(where, "cerealbox") == pytest.approx(part)
    glimpses.frame((1.0, 2.5, 0.0), 0.0, -0.2, [], [table.id], tops_label="cerealbox")
    assert mind.cmap.objects.remaining(where, "cerealbox") == pytest.approx(0.36)



def test_a_dt_look_for_the_target_is_a_look_for_its_supports(corridor) -> None:
    """A DT frame looks for the target's supports as the watch's frames do: one that shows
    no desk lowers the room's count of desks not found yet where it had a free view, and
    with it the target's share on them. It used to look for the target alone, so a room
    the DT had searched through kept its prior count of desks, and the stopping rule kept
    it worth searching."""
    mind, builder, executor = corridor
    if executor.glimpses is None:
        executor.enable_glimpses()
    room, _ = _here(mind)
    target = builder.task.target
    supports = [s for s in builder.supports if s != target]
    assert supports
    before = {s: mind.cmap.objects.remaining(room, s) for s in supports}
    p_before = mind.cmap.p_unsearched(target, room)
    asked = _record_frames(executor, hide=supports)  # no desk shows
    search = executor.view_cone_search(target, "in", room)
    for yaw in (0.0, 1.57, 3.14, -1.57):
        executor.robot.turn_to(yaw)
        search._look(target, "in", room)
    assert asked and set(supports) <= set(asked[0])
    after = {s: mind.cmap.objects.remaining(room, s) for s in supports}
    assert all(after[s] < before[s] for s in supports), (before, after)
    assert mind.cmap.p_unsearched(target, room) < p_before


def test_a_frame_while_a_confirmed_target_waits_for_its_room_looks_for_the_target_only(
        corridor) -> None:  # noqa: ANN001
    """A target confirmed before the map had a room for it waits for the scan behind; what
    a frame shows of supports meanwhile no longer matters, and confirming a desk seen in
    passing would take another frame before the target could be reported."""
    _, builder, executor = corridor
    if executor.glimpses is None:
        executor.enable_glimpses()
    asked = _record_frames(executor)
    executor.watch()
    assert set(builder.supports) <= set(asked[-1])  # as a rule the watch asks for supports too
    executor.sensing.unplaced.append(SimpleNamespace(label=builder.task.target,
                                              position=(50.0, 50.0, 0.8)))
    executor.watch()
    assert asked[-1] == [builder.task.target]


def _record_frames(executor, hide: Sequence[str] = ()) -> list[list[str]]:  # noqa: ANN001
    """Put a proxy of the executor's robot in its place that records the labels each frame
    asks the detector for, and drops detections of the labels in `hide`."""
    asked: list[list[str]] = []
    robot = executor.robot

    class Recording:
        def __getattr__(self, name):  # noqa: ANN001, ANN204
            return getattr(robot, name)

        def detect(self, labels):  # noqa: ANN001, ANN202
            asked.append(list(labels))
            return [s for s in robot.detect(labels) if s.label not in hide]

    executor.robot = Recording()
    return asked
