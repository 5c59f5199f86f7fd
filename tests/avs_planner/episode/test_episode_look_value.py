"""A look around turns only to the headings whose frame is worth its time by the planner's
objective (`Glimpses.frame_value`, `Sensing.look_around` with `look_by_value`): a heading
where R x P(the frame shows a wanted label) is below the frame's seconds costs neither a
turn nor a frame, unless the frame would see space outside the rooms the robot has
entered."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest

from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.viewcones import candidate_cells
from avs_planner.harness import Episode, EpisodeSpec

P_DETECT = 0.64


def _glimpses(mind, executor) -> Glimpses:  # noqa: ANN001
    return Glimpses(mind, executor.camera, p_detect=P_DETECT)


def test_a_frames_value_is_p_detect_times_the_unseen_share_in_view(corridor) -> None:
    mind, _, executor = corridor
    x, y = mind.place_map.places[mind.place_map.current_place].position
    points, rooms = candidate_cells(mind)
    priced = beyond = 0
    for k in range(8):
        pose = (x, y, k * math.pi / 4)
        g = _glimpses(mind, executor)
        value = g.frame_value(pose, 0.0, -0.2, ["cerealbox"], lambda label, room: 0.5)
        if g._sees_beyond(pose, 0.0):
            assert value == math.inf
            beyond += 1
            continue
        priced += 1
        seen = g.in_view(points, pose, 0.0, -0.2, executor.camera.support_height)
        expect = sum(P_DETECT * 0.5 * float(np.sum(seen & (rooms == room)))
                     / float(np.sum(rooms == room)) for room in set(rooms[seen]))
        assert value == pytest.approx(expect)
        assert g.frame_value(pose, 0.0, -0.2, ["cerealbox"],
                             lambda label, room: 1.0) == pytest.approx(2.0 * value)
        if value > 0.0:
            # a frame from here looked at those cells: from this standpoint they are no new
            # chance; from a metre back they are one, at (1 - p_detect) of a fresh cell's
            g.frame(pose, 0.0, -0.2, ["cerealbox"])
            mind.cmap.objects._glimpsed.clear()
            assert g.frame_value(pose, 0.0, -0.2, ["cerealbox"],
                                 lambda label, room: 0.5) == 0.0
    assert priced and beyond, (priced, beyond)  # the corridor has both kinds of heading


WORLD = """
name: two-rooms
size: [8.0, 5.0]
rooms:
  - {name: hall, category: corridor, rect: [0.0, 0.0, 8.0, 2.0]}
  - {name: meet, category: meeting_room, rect: [0.0, 2.0, 8.0, 5.0]}
doors:
  - {rooms: [hall, meet], at: [6.0, 2.0], width: 1.0}
furniture:
  - {name: table1, label: table, room: meet, pose: [4.0, 3.8, 0.0], size: [1.2, 0.8, 0.75]}
objects:
  - {name: cup1, label: cup, on: table1, offset: [0.1, 0.0], size: [0.08, 0.08, 0.1]}
robot: {model: pr2, start: [1.5, 1.0, 0.0]}
"""


def _episode(events: list[dict]) -> Episode:
    """An episode in the two-room world with the switching look round (glimpses, six
    headings, `look_by_value`)."""
    episode = Episode(EpisodeSpec.from_dict({"target": "cerealbox", "world_file": WORLD}),
                      events.append)
    executor = episode.executor
    executor.config = replace(executor.config, glimpses=True, look_by_value=True,
                              look_headings=6)
    executor.enable_glimpses()
    return episode


@pytest.fixture()
def look():
    """`_episode` and its trace's events; closed after the test."""
    events: list[dict] = []
    episode = _episode(events)
    try:
        yield episode, events
    finally:
        episode.trace.close()
        episode.robot.world.close()


def _second_look(episode: Episode, events: list[dict],
                 before: Callable[[], None] = lambda: None) -> list[int]:
    """Look around at the start, drive 2.5 m along the hall, (`before`), look around
    again: the headings the second look skipped."""
    sensing = episode.executor.sensing
    sensing.look_around()  # the first: everything unknown, every heading is looked at
    assert not [e for e in events if "look_skipped" in e]
    episode.executor.drive_to((4.0, 1.0))
    before()
    events.clear()
    sensing.look_around()
    return [k for e in events if "look_skipped" in e for k in e["look_skipped"]]


def test_a_look_around_skips_the_headings_not_worth_a_frame(look) -> None:
    episode, events = look
    robot = episode.robot
    frames: list[float] = []
    detect = robot.detect
    robot.detect = lambda labels: frames.append(robot.clock) or detect(labels)
    skipped = _second_look(episode, events)
    room = episode.mind.place_map.room_of(episode.mind.place_map.current_place)
    # a cereal box in the hall is unlikely: R x P of a heading that sees only a part of
    # the mapped hall is below a frame's second; the laser's half (180) is always turned to
    assert episode.mind.cmap.p_object_at("cerealbox", room) < 0.03
    assert skipped and 180 not in skipped
    body = episode.mind.body
    full = 5 * body.turn_time(math.pi / 3) + 6 * body.sensing_time + 2 * body.scan_time
    frames.clear()
    clock = robot.clock
    episode.executor.sensing.look_around()
    # the same spot again: no cheaper than the look before it skipped, and never more
    # frames than the headings looked at (a detection's confirming frames aside)
    again = [k for e in events if "look_skipped" in e for k in e["look_skipped"]]
    assert set(skipped) <= set(again[len(skipped):])
    assert robot.clock - clock < full
    assert len(frames) <= 6 - len(again[len(skipped):]) + 2, frames


def test_a_likely_label_is_looked_for_at_every_new_heading(look) -> None:
    episode, events = look
    episode.mind.cmap.p_object_at = lambda *a, **k: 1.0  # the map is sure it is here
    assert _second_look(episode, events) == []


def test_without_look_by_value_every_heading_is_looked_at(look) -> None:
    episode, events = look
    episode.executor.config = replace(episode.executor.config, look_by_value=False)
    episode.executor.sensing.look_around()
    episode.executor.sensing.look_around()
    assert not [e for e in events if "look_skipped" in e]


def test_a_remembered_sighting_in_view_is_looked_at() -> None:
    """A spot the building's memory holds a wanted object at is looked at, whatever the
    map's P for the room: the heading the second look skipped is taken when a sighting of
    the target stands 2 m along it."""
    from avs_planner.episode.memory import Sighting

    def second(remember: bool) -> list[int]:
        events: list[dict] = []
        episode = _episode(events)
        try:
            def place_sighting() -> None:
                x, y, yaw = episode.robot.pose
                heading = yaw + math.radians(skipped[0])
                episode.mind.remembered.append(Sighting(
                    "cerealbox", (x + 2.0 * math.cos(heading), y + 2.0 * math.sin(heading),
                                  episode.executor.camera.support_height), seen_at=0.0))

            return _second_look(episode, events, place_sighting if remember else lambda: None)
        finally:
            episode.trace.close()
            episode.robot.world.close()

    skipped = second(False)
    assert skipped
    assert skipped[0] not in second(True)
