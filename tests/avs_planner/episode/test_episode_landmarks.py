"""Room landmarks (`episode/landmarks.py`): furniture asked for in every frame, confirmed by
the frames that had its spot in view, evidence for its room's category."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from avs_planner.episode.context import FrameView, Listener
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.landmarks import RoomLandmarks, landmark_labels
from conceptual_map.knowledge import load_knowledge
from conceptual_map.metric import CellState


@dataclass
class Seen:
    label: str
    position: tuple[float, float, float]
    sid: int = 0


def test_landmarks_are_the_furniture_labels_not_asked_anyway() -> None:
    knowledge = load_knowledge()
    labels = landmark_labels(knowledge, ["cerealbox", "table", "counter", "shelf"])
    assert {"toilet", "fridge", "sofa", "desk", "sink"} <= set(labels)
    # a label some relation puts on or in a support is no landmark; asked ones are left out
    assert not {"cup", "book", "stapler", "cerealbox", "keyboard"} & set(labels)
    assert not {"table", "counter", "shelf"} & set(labels)


def _landmarks(executor):  # noqa: ANN001, ANN202
    ctx = executor.context
    events: list[tuple[str, dict]] = []
    ctx.emit = lambda kind, **fields: events.append((kind, fields))
    marks = RoomLandmarks(ctx, ("toilet", "fridge"), executor.sensing.known_near,
                          executor.glimpses or Glimpses(ctx.mind, ctx.camera, 1.0))
    return marks, events


def _free_heading(mind, x: float, y: float) -> float:  # noqa: ANN001
    """A heading from (x, y) with known free floor 1.5 m ahead (a spot the frame can see)."""
    states = mind.grid.state_grid()
    for k in range(16):
        yaw = 2 * math.pi * k / 16
        cells = [mind.grid.cell_of((x + d * math.cos(yaw), y + d * math.sin(yaw)))
                 for d in np.arange(0.3, 1.8, 0.1)]
        ok = all(mind.grid.contains(c) and states[c] == CellState.FREE for c in cells)
        if ok:
            return yaw
    raise AssertionError("no free heading in the test map")


def test_a_landmark_seen_in_most_frames_that_show_its_spot_is_evidence_for_its_room(
        corridor) -> None:  # noqa: ANN001
    mind, _, executor = corridor
    room = mind.place_map.room_of(mind.place_map.current_place)
    x, y = mind.place_map.places[mind.place_map.current_place].position
    yaw = _free_heading(mind, x, y)
    spot = (x + 1.5 * math.cos(yaw), y + 1.5 * math.sin(yaw), 0.4)
    view = FrameView((x, y, yaw), 0.0, 0.0)
    marks, events = _landmarks(executor)
    before = dict(mind.cmap.room_category(room))
    marks.observe([Seen("toilet", spot)], view)
    assert marks.confirmed == 0 and not [o for o in mind.objects.values()
                                         if o.label == "toilet"]
    # a frame that shows another label at the spot and not this one counts against it
    marks.observe([Seen("fridge", spot)], view)
    assert [(c.label, c.hits, c.misses) for c in marks.candidates] == [
        ("toilet", 1, 1), ("fridge", 1, 0)]
    marks.observe([Seen("toilet", (spot[0] + 0.1, spot[1], 0.4))], view)
    marks.observe([Seen("toilet", (spot[0], spot[1] + 0.1, 0.4))], view)
    assert marks.confirmed == 0  # at 1.5 m a phantom falls that near in 3% of frames
    marks.observe([Seen("toilet", spot)], view)
    toilets = [o for o in mind.objects.values() if o.label == "toilet"]
    assert marks.confirmed == 1 and len(toilets) == 1 and toilets[0].room == room
    assert mind.cmap.room_category(room)["bathroom"] > before["bathroom"] + 0.2
    assert events[-1][1]["landmark"] is True and events[-1][1]["hits"] == 4
    # the same toilet seen again is the known one, not a second toilet
    for _ in range(3):
        marks.observe([Seen("toilet", spot)], view)
    assert marks.confirmed == 1


def test_a_spot_in_view_without_the_label_counts_against_it(corridor) -> None:  # noqa: ANN001
    """Phantoms that fall near each other now and then are no landmark: the frames between
    them had the spot in view and did not show it."""
    mind, _, executor = corridor
    x, y = mind.place_map.places[mind.place_map.current_place].position
    yaw = _free_heading(mind, x, y)
    spot = (x + 1.5 * math.cos(yaw), y + 1.5 * math.sin(yaw), 0.4)
    view = FrameView((x, y, yaw), 0.0, 0.0)
    away = FrameView((x, y, yaw + math.pi), 0.0, 0.0)  # the spot behind the camera
    marks, _ = _landmarks(executor)
    for k in range(12):
        marks.observe([Seen("toilet", spot)] if k % 4 == 0 else [], view)
    assert marks.confirmed == 0
    assert not [c for c in marks.candidates if c.hits >= 3]
    # frames that did not have the spot in view say nothing about it
    marks2, _ = _landmarks(executor)
    marks2.observe([Seen("toilet", spot)], view)
    for _ in range(10):
        marks2.observe([], away)
    assert [c.misses for c in marks2.candidates] == [0]
    for _ in range(2):
        marks2.observe([Seen("toilet", spot)], view)
    assert marks2.confirmed == 1


def test_every_frame_asks_for_the_landmarks_and_the_skill_gets_its_own_labels(corridor) -> None:  # noqa: ANN001
    """One frame for the skill and the listeners (no extra sensing time): the robot is asked
    for both, each gets the detections of its labels."""
    _, _, executor = corridor
    ctx = executor.context
    asked: list[list[str]] = []
    heard: list[list[str]] = []

    views: list[FrameView] = []

    class Camera:
        pose = (1.0, 2.0, 0.5)

        def detect(self, labels):  # noqa: ANN001, ANN202
            asked.append(list(labels))
            return [Seen("toilet", (1.0, 0.0, 0.4)), Seen("cerealbox", (1.0, 0.5, 0.9))]

        def look(self, pan: float, tilt: float) -> None:
            pass

    ctx.robot = Camera()  # type: ignore[assignment]

    def hear(seen, view: FrameView) -> None:  # noqa: ANN001
        heard.append([s.label for s in seen])
        views.append(view)

    ctx.listeners.append(Listener(("toilet",), hear))
    clock_frames = len(asked)
    ctx.look(0.3, -0.2)  # the skills point the head here: listeners learn where it looked
    seen = ctx.detect(["cerealbox"])
    assert [s.label for s in seen] == ["cerealbox"]
    assert asked[clock_frames:] == [["cerealbox", "toilet"]] and heard == [["toilet"]]
    assert views == [FrameView((1.0, 2.0, 0.5), 0.3, -0.2)]


@pytest.mark.parametrize("on", [True, False])
def test_the_switching_strategy_listens_for_landmarks_unless_told_not_to(
        corridor, switching_loop, on: bool) -> None:  # noqa: ANN001
    from avs_planner.episode.trace import Trace
    from avs_planner.strategies.switching.loop import LoopConfig

    _, builder, executor = corridor
    switching_loop(builder, executor, Trace(lambda: executor.robot.clock, None, None),
                   LoopConfig(landmarks=on))
    heard = {lb for listener in executor.context.listeners for lb in listener.labels}
    assert ("toilet" in heard) is on and (executor.landmarks is not None) is on
    assert "cerealbox" not in heard  # the target is asked for anyway
