"""Looking for the target without the DT: turn on the spot, detect, confirm with a second
frame; a confirmed detection becomes a known object (the baselines' only way to find)."""

from __future__ import annotations

import math

from avs_planner.episode.mind import KnownObject
from avs_planner.strategies.context import SearchContext

LOOK_DISTANCE = 2.0  # m: where the camera's centre line meets support height
SUPPORT_HEIGHT = 0.7  # m: a typical table top


def look_all_round(ctx: SearchContext, headings: int) -> KnownObject | None:
    """Look in `headings` directions from here; the first confirmed target, or None."""
    robot = ctx.robot
    tilt = -math.atan2(ctx.body.camera_height - SUPPORT_HEIGHT, LOOK_DISTANCE)
    yaw = robot.pose[2]
    for k in range(headings):
        robot.turn_to(yaw + 2 * math.pi * k / headings)
        robot.look(0.0, tilt)
        found = _look(ctx)
        if found is not None:
            return found
    return None


def _look(ctx: SearchContext) -> KnownObject | None:
    """One view: a detection of the target that a second frame repeats nearby."""
    ex, label = ctx.executor, ctx.target
    ex.stats.views += 1
    first = [s for s in ctx.robot.detect([label]) if s.label == label]
    for s in first:
        ex.stats.detections.append((s.position[0], s.position[1], label, True))
    if not first:
        ctx.trace.emit("observation", label=label, detected=False)
        return None
    agree = ex.config.agree[0]
    again = [s for s in ctx.robot.detect([label]) if s.label == label
             and math.dist(s.position, first[0].position) <= agree]
    ctx.trace.emit("observation", label=label, detected=bool(again),
                   position=[round(v, 2) for v in first[0].position])
    if not again:
        return None
    return _confirm(ctx, first[0])


def _confirm(ctx: SearchContext, seen) -> KnownObject | None:  # noqa: ANN001 - a Seen
    """The detection as a known object, if it lies in a room of the task's category."""
    mind = ctx.mind
    if mind.room_at(seen.position[:2]) is None:
        return None
    obj = mind.add_object(ctx.target, seen.position)
    ctx.executor.found_sids[obj.id] = seen.id
    if ctx.category is not None:
        belief = mind.cmap.room_category(obj.room)
        if max(belief, key=belief.get) != ctx.category:
            return None
    return obj
