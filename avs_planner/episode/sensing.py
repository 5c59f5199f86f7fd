"""Sensing along the way: what the executor's scanner and detector do between and within
the steps of a plan.

The first view of a place (`look_around`), a scan after every leg driven (`sense`), the
detector watching for the target as the robot moves (`watch`), frames taken in passing as
evidence (`glimpse`, `episode/glimpses.py`), more frames before a detection counts
(`confirm`), and a last look before the target is reported (`verify_report`,
`episode/verifying.py`). The executor (`episode/executor.py`) runs the plan's steps and hands
off to these: every step and every strategy senses the same way, and the two concerns made
one file of more than 500 lines.

Functions that call back into the executor (its watch, confirm, drive, ...) or update its
sensing state (detections not yet placed in a room, objects seen while moving) take the
executor, so a method replaced on one executor (a test's spy) is the one they use; the others
take only what they read.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.outcome import SeenLike
from avs_planner.episode.robot_api import Robot
from avs_planner.episode.verifying import step_back, verify_distance
from avs_planner.episode.viewcones import CameraModel

if TYPE_CHECKING:
    from avs_planner.episode.executor import Executor, ExecutorConfig


def look_around(ex: Executor) -> None:
    """Scan, turn half round, scan again: the first view of a place (the place map is
    updated once, after both scans). The detector watches in `look_headings` directions
    spread evenly over the turn (2: ahead and behind)."""
    headings = max(2, ex.config.look_headings)
    yaw = ex.robot.pose[2]
    ex.mind.integrate(ex.robot.scan())
    found = ex.watch()
    half = headings // 2
    for k in range(1, headings):
        if found is not None and k > half:  # the target is here: the map is done
            break
        if ex._unplaced and k < half:
            # the target is confirmed and waits only for the scan behind to give it a
            # room: turn straight there (a frame at each heading on the way cost a second
            # on every target seen in the first frame)
            continue
        ex.robot.turn_to(yaw + 2.0 * math.pi * k / headings)
        if k == half:
            found = ex._sense([ex.robot.pose], watch=True) or found
        elif found is None:
            found = ex.watch()


def sense(ex: Executor, poses: list[tuple[float, float, float]], watch: bool = False
          ) -> KnownObject | None:
    """Integrate a scan from `poses`; the detector watches when asked or at a new place.
    Returns the target the watch confirmed, or one confirmed earlier that the scan placed
    in a room, if any."""
    before = ex.mind.place_map.current_place
    events = ex.mind.sense(ex.robot.scan(), poses, ex.robot.clock)
    place = ex.mind.place_map.current_place
    if place is not None and (place != before or place not in ex.mind.classified):
        ex._classify()
    seen = None
    if watch or (place is not None and place != before):
        seen = ex.watch()
    if ex._unplaced:
        # a target confirmed before the map had a room for it (the very first look) is
        # found now that the scan gave it one: the caller stops as for a watch's find
        seen = place_seen(ex) or seen
    if events:
        kinds: dict[str, int] = {}
        for e in events:
            key = f"{e.kind.value}_{e.change.value}"
            kinds[key] = kinds.get(key, 0) + 1
        ex.emit("belief", map_events=kinds)
    record_pose(ex.robot, ex.mind, ex.stats.path)
    return seen


def watch(ex: Executor) -> KnownObject | None:
    """Keep the detector on while moving: look ahead for the target (a second frame must
    repeat a detection); a new confirmed target becomes a known object whose atoms reach
    the monitor with the next step's outcome (it may match a virtual object). The same
    frame looks for the supports the problem knows of: a new one, confirmed, becomes a
    known object too, and a frame that shows none of a label is evidence where it looked
    (`episode/glimpses.py`)."""
    if not ex.watching:
        return None
    label = ex.builder.task.target
    ex.robot.look(0.0, ahead_tilt(ex.camera))
    # once a target is confirmed and only waits for the scan to give it a room, what the
    # frame shows of supports no longer matters: confirming a desk seen in passing took
    # a frame (a second) before the target could be reported
    glimpsing = ex.glimpses is not None and not ex._unplaced
    labels = [label, *ex.builder.supports] if glimpsing else [label]
    frame = ex.robot.detect(labels)
    first = [s for s in frame if s.label == label]
    if glimpsing:
        glimpse(ex, frame, labels)
    if not first or ex.known_near(first[0]):
        return None
    seen = first[0]
    again = ex.confirm(seen)
    ex.emit("observation", label=label, detected=bool(again), watching=True,
            position=[round(v, 2) for v in seen.position])
    if not again:
        return None
    ex._unplaced.append(seen)
    return place_seen(ex)


def glimpse(ex: Executor, frame: list[SeenLike], labels: list[str],
            head: tuple[float, float] | None = None) -> None:
    """What one frame (the head at `head`, pan and tilt; by default ahead, as the watch
    looks) says of `labels`: those it did not show are less likely where it looked;
    supports it shows (seen again in a second frame) become known. The tops of known
    supports count for the target only when the target is one of `labels`."""
    assert ex.glimpses is not None
    target = ex.builder.task.target
    shown = {s.label for s in frame}
    unseen = [lab for lab in labels if lab not in shown]
    pan, tilt = head if head is not None else (0.0, ahead_tilt(ex.camera))
    changed = ex.glimpses.frame(ex.robot.pose, pan, tilt, unseen,
                                ex._supports_of(target) if target in unseen else (),
                                tops_label=target,
                                shown={lab: [s.position for s in frame if s.label == lab]
                                       for lab in labels if lab in shown})
    if changed:
        ex.emit("belief", glimpsed=changed)
    for seen in frame:
        if seen.label == target or ex.known_near(seen):
            continue
        if ex.mind.room_at(seen.position[:2]) is None:
            continue
        if not ex.confirm(seen, needed=1, frames=1, agree=ex.config.agree[1]):
            continue
        obj = ex.mind.add_object(seen.label, seen.position)
        ex.seen_while_moving[obj.id] = {
            ("label-of", obj.id, seen.label), ("detected", obj.id),
            ("related", obj.id, "in", obj.room)}
        ex.emit("observation", label=seen.label, detected=True, watching=True,
                position=[round(v, 2) for v in seen.position], object=obj.id)


def supports_of(mind: Mind, label: str) -> list[str]:
    """Known objects `label` may lie on (the knowledge lists the relation)."""
    listed = mind.cmap.knowledge.relation_lambda
    return [oid for oid, obj in mind.objects.items()
            if (label, "on", obj.label) in listed]


def confirm(robot: Robot, config: ExecutorConfig, seen: SeenLike, needed: int | None = None,
            frames: int | None = None, agree: float | None = None) -> bool:
    """`needed` more frames (default `confirm_needed`) of up to `frames` (default
    `confirm_frames`) see the label again within `agree` metres. Without the DT's belief,
    a report rests on this: a phantom (5% of frames, anywhere in view) that repeats twice
    at the same spot is practically never seen, while a real object missed in 1 frame of
    5 still passes 9 times in 10. One short with some frame agreeing is ambiguous: up to
    `confirm_extra` more frames are taken (once)."""
    cfg = config
    agree = cfg.agree[0] if agree is None else agree
    needed = cfg.confirm_needed if needed is None else needed
    frames = cfg.confirm_frames if frames is None else frames
    hits = k = 0
    extended = False
    while k < frames:
        if any(s.label == seen.label and math.dist(s.position, seen.position) <= agree
               for s in robot.detect([seen.label])):
            hits += 1
        k += 1
        if hits >= needed:
            return True
        if hits + frames - k < needed:
            if extended or hits == 0 or hits < needed - 1 or cfg.confirm_extra <= 0:
                return False
            # one short, and some frame agreed: ambiguous, so look again
            frames, extended = k + cfg.confirm_extra, True
    return False


def verify_report(ex: Executor, obj) -> bool:  # noqa: ANN001 - a known object or a Seen
    """`verify` from a camera distance where frames agree by accident at most
    `MAX_ACCIDENTAL` of the time (`episode/verifying.py`): stepping back there first when
    the robot stands closer and can reach such a spot. Without a body: `verify`."""
    body = ex.mind.body
    if body is None:
        return ex.verify(obj)
    x, y, _ = ex.robot.pose
    distance = math.dist((x, y, body.camera_height), obj.position)
    needed = min(verify_distance(ex.config.agree[0], body.hfov, body.vfov),
                 0.9 * body.detect_range)
    if distance < needed:
        stand = step_back(ex.mind.grid, ex.mind.config.robot_radius, ex.robot.pose,
                          body.camera_height, obj.position, needed)
        ex.emit("action", action="(step-back)", status="start" if stand else "failed",
                distance=round(distance, 2), needed=round(needed, 2))
        if stand is not None:
            ex.drive_to(stand)
    return ex.verify(obj)


def verify(ex: Executor, obj: KnownObject) -> bool:
    """Face `obj` and look at it: True when one of `verify_frames` frames sees its label
    within `agree` m of where it was found (always True with 0 frames)."""
    frames = ex.config.verify_frames
    if frames <= 0:
        return True
    x, y, _ = ex.robot.pose
    dx, dy = obj.position[0] - x, obj.position[1] - y
    ex.robot.turn_to(math.atan2(dy, dx))
    ex.robot.look(0.0, -math.atan2(ex.camera.height - obj.position[2],
                                   max(math.hypot(dx, dy), 0.1)))
    seen = ex.confirm(obj, needed=1, frames=frames)
    ex.emit("observation", label=obj.label, detected=seen, verifying=True,
            position=[round(v, 2) for v in obj.position])
    return seen


def place_seen(ex: Executor) -> KnownObject | None:
    """Confirmed detections become known objects once the place map has a room for them
    (the very first look comes before the first place)."""
    obj = None
    for seen in list(ex._unplaced):
        room = ex.mind.room_at(seen.position[:2])
        if room is None and seen.label == ex.builder.task.target:
            # a target seen through a door is reported from here; its room (evidence
            # about the room's category) is the nearest known one until it is entered
            room = ex.mind.nearest_room(seen.position[:2])
        if room is None:
            continue
        ex._unplaced.remove(seen)
        obj = ex.mind.add_object(seen.label, seen.position, room=room)
        ex.found_sids[obj.id] = seen.id
        ex.seen_while_moving[obj.id] = {
            ("label-of", obj.id, seen.label), ("detected", obj.id),
            ("related", obj.id, "in", obj.room)}
    return obj


def known_near(mind: Mind, reach: float, seen: SeenLike) -> bool:
    """A detection of an object the mind already knows (same label, within `reach`
    metres)."""
    return any(obj.label == seen.label and math.dist(obj.position[:2], seen.position[:2])
               <= reach for obj in mind.objects.values())


def ahead_tilt(camera: CameraModel) -> float:
    """The head's tilt while watching: towards support height `look_distance` m ahead."""
    return -math.atan2(camera.height - camera.support_height, camera.look_distance)


def classify(robot: Robot, mind: Mind, doorway_clearance: float, emit: Callable[..., None]
             ) -> None:
    """Ask the place classifier, unless the robot stands within `doorway_clearance` m of a
    door (it would see the room beyond and credit it to this place); a reading that cannot
    be used is a warning in the trace, never dropped silently."""
    if mind.near_door(robot.pose[:2], doorway_clearance):
        return
    observed = robot.classify_place()
    if observed is None:
        emit("warning", source="place_classifier", detail="no reading here")
        return
    unused = mind.observe_appearance(observed)
    if unused is not None:
        emit("warning", source="place_classifier", observed=observed, detail=unused)


def record_pose(robot: Robot, mind: Mind, path: list[tuple[float, float, float, str]]
                ) -> None:
    """Append the robot's pose and its room's most likely category (if any) to `path`."""
    x, y, yaw = robot.pose
    room = mind.room_at((x, y))
    category = ""
    if room is not None and mind.cmap.graph.has_room(room):
        belief = mind.cmap.room_category(room)
        category = max(belief, key=belief.get)
    path.append((x, y, yaw, category))
