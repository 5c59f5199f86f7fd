"""Looking for the target without the DT: turn on the spot, detect, confirm with more frames
(`Executor.confirm`), verify before reporting (`verify_report`); a confirmed and verified
detection becomes a known object (the baselines' and FLAP's only way to find).

Why the verification. A phantom (the detector's false positive, `fp_rate` of frames) lands
where a random ray through the image meets a surface. Frames agree on a spot when they see the
label within `agree` (0.25 m) of it, and the chance that a phantom does so by accident is the
share of the view's cross-section at that distance within `agree` of the spot. Two metres
away that is about 5% of a 60 x 45 degree view; facing a wall 0.4 m away the whole view is
within 0.25 m of every point on it, so every phantom agrees and "two of three frames" only
asks for phantoms in two more frames. One search in 50 generated office worlds reported a
stapler that way (`most-likely-room`, world 23: a phantom at 0.39 m, on the wall in front of
the robot, repeated in the next two frames). So before a report the robot steps back to where
agreement means something (`accidental_agreement` at most `MAX_ACCIDENTAL`) when it can
reach such a spot, faces the detection and looks again (`Executor.verify`: one of
`verify_frames` frames must see it within `agree`), as the switching loop verifies.
"""

from __future__ import annotations

import math

import numpy as np

from avs_planner.episode.mind import KnownObject
from avs_planner.strategies.context import SearchContext
from conceptual_map.metric import PathQueryError, distance_field

LOOK_DISTANCE = 2.0  # m: where the camera's centre line meets support height
SUPPORT_HEIGHT = 0.7  # m: a typical table top
MAX_ACCIDENTAL = 0.1  # a report's verification must come from where a phantom agrees by
# chance at most this often (see the module's doc)
STEP_BACK_TURNS = (0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5)  # rad off the line from the object
# to the robot, tried in this order for the standpoint of a verification from further away


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


def accidental_agreement(distance: float, agree: float, hfov: float, vfov: float) -> float:
    """The chance that a phantom in a view lands within `agree` m of a point `distance` m
    from the camera (the disc's share of the view's cross-section there, at most 1)."""
    section = 4.0 * distance**2 * math.tan(hfov / 2.0) * math.tan(vfov / 2.0)
    return 1.0 if section <= 0.0 else min(1.0, math.pi * agree**2 / section)


def verify_distance(agree: float, hfov: float, vfov: float,
                    accidental: float = MAX_ACCIDENTAL) -> float:
    """The camera distance beyond which `accidental_agreement` is at most `accidental`."""
    return agree * math.sqrt(math.pi / (4.0 * accidental * math.tan(hfov / 2.0)
                                        * math.tan(vfov / 2.0)))


def verify_report(ctx: SearchContext, seen) -> bool:  # noqa: ANN001 - a Seen or known object
    """Before a confirmed detection is reported: from a camera distance where frames agree by
    accident at most `MAX_ACCIDENTAL` of the time (stepping back there first when the robot
    stands closer and can reach such a spot), face it and look again (`Executor.verify`)."""
    body, ex = ctx.body, ctx.executor
    agree = ex.config.agree[0]
    x, y, _ = ctx.robot.pose
    camera = (x, y, body.camera_height)
    needed = min(verify_distance(agree, body.hfov, body.vfov), 0.9 * body.detect_range)
    if math.dist(camera, seen.position) < needed:
        stand = _step_back(ctx, seen.position, needed)
        ctx.trace.emit("action", action="(step-back)", status="start" if stand else "failed",
                       distance=round(math.dist(camera, seen.position), 2),
                       needed=round(needed, 2))
        if stand is not None:
            ex.drive_to(stand)
    return ex.verify(seen)


def _step_back(ctx: SearchContext, position, distance: float  # noqa: ANN001 - xyz
               ) -> tuple[float, float] | None:
    """A reachable free spot whose camera is `distance` m from `position`, on the robot's
    side of it (the line from it to the robot, turned by `STEP_BACK_TURNS` in turn)."""
    mind, body = ctx.mind, ctx.body
    grid = mind.grid
    x, y, _ = ctx.robot.pose
    dz = body.camera_height - position[2]
    flat = math.sqrt(max(distance**2 - dz**2, 0.0))
    if flat <= 0.0:
        return None
    try:
        reach = distance_field(grid, (x, y), mind.config.robot_radius)
    except PathQueryError:  # the robot off the map: no step back
        return None
    away = math.atan2(y - position[1], x - position[0])
    for turn in STEP_BACK_TURNS:
        goal = (position[0] + flat * math.cos(away + turn),
                position[1] + flat * math.sin(away + turn))
        cell = grid.cell_of(goal)
        if grid.contains(cell) and np.isfinite(reach[tuple(cell)]):
            return goal
    return None


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
