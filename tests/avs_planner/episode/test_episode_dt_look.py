"""A DT look (PROCESSVIEWCONE): two frames must agree; when they split, a third decides."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import pytest


def _seen(x: float, y: float) -> SimpleNamespace:
    return SimpleNamespace(label="cerealbox", position=(x, y, 0.8))


def _look(executor, frames: list, tiebreak: bool = True):  # noqa: ANN001, ANN202
    executor.config = replace(executor.config, dt_tiebreak=tiebreak)
    search = executor.view_cone_search("cerealbox", "in", "room1")
    script = iter(frames)
    taken = []

    def detect_once(*_args):  # noqa: ANN002, ANN202
        taken.append(1)
        return next(script)

    search._detect_once = detect_once
    return search._look("cerealbox", "in", "room1"), len(taken)


@pytest.mark.parametrize(("frames", "found", "taken"), [
    ([_seen(2.0, 1.0), _seen(2.1, 1.0)], True, 2),  # both agree: two frames, as before
    ([_seen(2.0, 1.0), None, _seen(2.05, 1.1)], True, 3),  # split: the third agrees
    ([_seen(2.0, 1.0), None, None], False, 3),  # split: the third does not
    ([_seen(2.0, 1.0), _seen(4.0, 1.0), None], False, 3),  # a second spot is no agreement
    ([None], False, 1),  # nothing: one frame
])
def test_a_split_look_is_decided_by_a_third_frame(corridor, frames, found, taken) -> None:
    _, _, executor = corridor
    match, count = _look(executor, frames)
    assert (match is not None) == found and count == taken
    if found:
        assert match is frames[0]


def test_without_the_tiebreak_a_split_look_is_a_miss(corridor) -> None:
    _, _, executor = corridor
    match, count = _look(executor, [_seen(2.0, 1.0), None, _seen(2.0, 1.0)], tiebreak=False)
    assert match is None and count == 2


def test_a_search_the_dt_would_not_look_in_is_settled_for_the_planner(corridor) -> None:
    """The DT, on its belief, finds no look worth its cost: asked again from the same state
    it would decide the same in no time, and the loop took that repeat for a livelock and
    gave up with the rest of the building unsearched. The location is settled instead;
    a search that looked counts once, as before."""
    from avs_planner.dt import DTStatus, ViewCone
    from avs_planner.dt.domain import ActionKind
    from avs_planner.episode.viewcones import ConeSet

    _, _, executor = corridor
    builder = executor.builder
    search = executor.view_cone_search("cerealbox", "in", "room1")
    no_look = SimpleNamespace(trace=[], status=DTStatus.REJECTED, detection=None)
    outcome = search._conclude(no_look, "cerealbox", "in", "room1", ConeSet((), 0.0, 0.0))
    assert outcome.detail == "rejected without looking"
    assert builder.failed_in[("cerealbox", "room1")] >= builder.config.max_failed_room_searches

    builder.failed_in.clear()
    cone = ViewCone("c0", (0.0, 0.0, 0.0), 0.4)
    look = SimpleNamespace(action=SimpleNamespace(kind=ActionKind.PROCESS_VIEW_CONE, cone=0))
    looked = SimpleNamespace(trace=[look], status=DTStatus.REJECTED, detection=None)
    outcome = search._conclude(looked, "cerealbox", "in", "room1", ConeSet((cone,), 0.8, 0.4))
    assert outcome.detail == "rejected"
    assert builder.failed_in[("cerealbox", "room1")] == 1
