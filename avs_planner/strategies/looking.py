"""Looking for the target without the DT: turn on the spot, detect, confirm with more frames
(`Executor.confirm`), verify before reporting (`verify_report`); a confirmed and verified
detection becomes a known object (the baselines' and FLAP's only way to find).

Why the verification: in frames taken close to a surface, phantoms land within the agreement
radius of each other (`episode/verifying.py`), so before a report the robot steps back to
where agreement means something and looks again (`Executor.verify_report`), as the
switching loop's REPORTPOSITION does.
"""

from __future__ import annotations

import math

from avs_planner.episode.mind import KnownObject
from avs_planner.episode.verifying import (  # noqa: F401 - re-exported for the baselines
    MAX_ACCIDENTAL,
    accidental_agreement,
    verify_distance,
)
from avs_planner.strategies.context import SearchContext

LOOK_DISTANCE = 2.0  # m: where the camera's centre line meets support height
SUPPORT_HEIGHT = 0.7  # m: a typical table top


def known_target(ctx: SearchContext) -> KnownObject | None:
    """A target the robot has confirmed already (e.g. its detector saw it while driving)."""
    for obj in ctx.mind.objects.values():
        if obj.label == ctx.target and _in_category(ctx, obj):
            return obj
    return None


def verified_target(ctx: SearchContext) -> KnownObject | None:
    """`known_target`, verified before it is reported (`checked`): the executor's watch
    confirms a target while driving by two of three frames, which a phantom on a wall close
    in front of the camera can pass. One that fails is forgotten, and the next is tried."""
    while (known := known_target(ctx)) is not None:
        if checked(ctx, known):
            return known
    return None


def checked(ctx: SearchContext, obj: KnownObject) -> bool:
    """`verify_report` for a known object; one not seen again is forgotten (the mind, the
    map and the executor's record of what it found), as the switching loop does."""
    if verify_report(ctx, obj):
        return True
    ctx.mind.forget_object(obj.id)
    ctx.executor.found_sids.pop(obj.id, None)
    ctx.trace.emit("belief", forgotten=obj.id, label=obj.label,
                   detail="not seen again when looked at before reporting")
    return False


def look_all_round(ctx: SearchContext, headings: int) -> KnownObject | None:
    """Look in `headings` directions from here; the first confirmed target, or None."""
    known = verified_target(ctx)
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
    obj = _confirm(ctx, first[0])
    return obj if obj is not None and checked(ctx, obj) else None


def verify_report(ctx: SearchContext, seen) -> bool:  # noqa: ANN001 - a Seen or known object
    """Before a confirmed detection is reported: from a camera distance where frames agree by
    accident at most `MAX_ACCIDENTAL` of the time, face it and look again
    (`Executor.verify_report`, as the switching loop's REPORTPOSITION does)."""
    return ctx.executor.verify_report(seen)


def _confirm(ctx: SearchContext, seen) -> KnownObject | None:  # noqa: ANN001 - a Seen
    """The detection as a known object, if it lies in a room of the task's category."""
    mind = ctx.mind
    # a target seen through a door counts from here: its room is the nearest known one
    room = mind.room_at(seen.position[:2]) or mind.nearest_room(seen.position[:2])
    if room is None:
        return None
    obj = mind.add_object(ctx.target, seen.position, room=room)
    ctx.executor.found_sids[obj.id] = seen.id
    return obj if _in_category(ctx, obj) else None


def _in_category(ctx: SearchContext, obj: KnownObject) -> bool:
    """The object's room is believed to be of the task's category (if the task names one)."""
    if ctx.category is None:
        return True
    belief = ctx.mind.cmap.room_category(obj.room)
    return max(belief, key=belief.get) == ctx.category
