"""Looking for the target without the DT: turn on the spot, detect, confirm with more frames
(`Executor.confirm`); a confirmed detection becomes a known object (the baselines' only way to
find)."""

from __future__ import annotations

import math

from avs_planner.episode.mind import KnownObject
from avs_planner.strategies.context import SearchContext

LOOK_DISTANCE = 2.0  # m: where the camera's centre line meets support height
SUPPORT_HEIGHT = 0.7  # m: a typical table top


def known_target(ctx: SearchContext) -> KnownObject | None:
    """A target the robot has confirmed already (e.g. its detector saw it while driving)."""
    for obj in ctx.mind.objects.values():
        if obj.label == ctx.target and _in_category(ctx, obj):
            return obj
    return None


def look_all_round(ctx: SearchContext, headings: int) -> KnownObject | None:
    """Look in `headings` directions from here; the first confirmed target, or None."""
    known = known_target(ctx)
    if known is not None:
        return known
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
    first = [s for s in ctx.robot.detect([label]) if s.label == label
             and not ex.known_near(s)]
    for s in first:
        ex.stats.detections.append((s.position[0], s.position[1], label, True))
    if not first:
        ctx.trace.emit("observation", label=label, detected=False)
        return None
    confirmed = ex.confirm(first[0])
    ctx.trace.emit("observation", label=label, detected=confirmed,
                   position=[round(v, 2) for v in first[0].position])
    if not confirmed:
        return None
    return _confirm(ctx, first[0])


def _confirm(ctx: SearchContext, seen) -> KnownObject | None:  # noqa: ANN001 - a Seen
    """The detection as a known object, if it lies in a room of the task's category."""
    mind = ctx.mind
    if mind.room_at(seen.position[:2]) is None:
        return None
    obj = mind.add_object(ctx.target, seen.position)
    ctx.executor.found_sids[obj.id] = seen.id
    return obj if _in_category(ctx, obj) else None


def _in_category(ctx: SearchContext, obj: KnownObject) -> bool:
    """The object's room is believed to be of the task's category (if the task names one)."""
    if ctx.category is None:
        return True
    belief = ctx.mind.cmap.room_category(obj.room)
    return max(belief, key=belief.get) == ctx.category
