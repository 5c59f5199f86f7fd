"""The look before a report (`Verifier.verify_report`): from a step back when the robot stands
close, and, when every frame from there missed, from where it stood again with two agreeing
frames of three (a view from the side may look past the shelf's side at what stands in it)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from avs_planner.episode import verifying
from avs_planner.episode.verifying import Verifier

OBJECT = (1.0, 0.0, 0.9)
CLOSE = (0.0, 0.0, 0.0)  # 1.1 m from the object's camera-height point: closer than needed
BACK = (-0.5, 0.5, 0.0)  # the step-back spot


class _Robot:
    def __init__(self) -> None:
        self.pose = CLOSE

    def turn_to(self, yaw: float) -> None:
        self.pose = (*self.pose[:2], yaw)


class _Sensing:
    """Of the frames from BACK `back_hits` show the object, from CLOSE `close_hits`."""

    def __init__(self, robot: _Robot, close_hits: int, back_hits: int) -> None:
        self.robot, self.close_hits, self.back_hits, self.calls = robot, close_hits, back_hits, []

    def confirm(self, seen, needed: int, frames: int) -> bool:  # noqa: ANN001
        at_back = math.dist(self.robot.pose[:2], BACK[:2]) < 0.1
        hits = self.back_hits if at_back else self.close_hits
        self.calls.append((self.robot.pose[:2], needed, frames))
        return hits >= needed


def _verifier(close_hits: int, frames: int = 3, back_hits: int = 0):
    robot = _Robot()
    events: list[dict] = []
    body = SimpleNamespace(camera_height=1.2, hfov=math.radians(60), vfov=math.radians(45),
                           detect_range=4.0)
    ctx = SimpleNamespace(
        robot=robot, camera=SimpleNamespace(height=1.2),
        mind=SimpleNamespace(body=body, grid=None, config=SimpleNamespace(robot_radius=0.25)),
        config=SimpleNamespace(agree=(0.25, 0.6), verify_frames=frames),
        emit=lambda kind, **kw: events.append({"type": kind, **kw}),
        look=lambda pan, tilt: None)

    def drive_to(goal):  # noqa: ANN001, ANN202
        robot.pose = (*goal, robot.pose[2])

    sensing = _Sensing(robot, close_hits, back_hits)
    return Verifier(ctx, SimpleNamespace(drive_to=drive_to), sensing), sensing, events


@pytest.fixture(autouse=True)
def _step_back_spot(monkeypatch):
    monkeypatch.setattr(verifying, "step_back", lambda *a, **k: BACK[:2])


def test_missed_from_the_step_back_it_is_looked_at_again_from_where_it_was_seen():
    verifier, sensing, events = _verifier(close_hits=2)
    assert verifier.verify_report(SimpleNamespace(label="book", position=OBJECT))
    (back, n1, _), (again, n2, _) = sensing.calls
    assert back == BACK[:2] and n1 == 1
    assert again == CLOSE[:2] and n2 == 2  # closer: two agreeing frames, not one
    steps = [e["status"] for e in events if e.get("action") == "(step-back)"]
    assert steps == ["start", "undone"]


def test_one_agreeing_frame_close_by_is_not_enough():
    verifier, sensing, _ = _verifier(close_hits=1)
    assert not verifier.verify_report(SimpleNamespace(label="book", position=OBJECT))
    assert len(sensing.calls) == 2


def test_seen_from_the_step_back_it_is_reported_from_there():
    verifier, sensing, events = _verifier(close_hits=3, back_hits=1)
    assert verifier.verify_report(SimpleNamespace(label="book", position=OBJECT))
    assert [c[0] for c in sensing.calls] == [BACK[:2]]
    assert [e["status"] for e in events if e.get("action") == "(step-back)"] == ["start"]


def test_with_one_verification_frame_there_is_no_second_look():
    verifier, sensing, _ = _verifier(close_hits=1, frames=1)
    assert not verifier.verify_report(SimpleNamespace(label="book", position=OBJECT))
    assert len(sensing.calls) == 1
