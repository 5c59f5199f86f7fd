"""The sensing skill: what the executor's scanner and detector do between and within the steps
of a plan.

The first view of a place (`Sensing.look_around`), a scan after every leg driven (`sense`),
the detector watching for the target as the robot moves (`watch`), frames taken in passing as
evidence (`glimpse`, `episode/glimpses.py`), more frames before a detection counts
(`confirm`), and the place classifier (`classify`). Every step and every strategy senses the
same way; the look before a report is `episode/verifying.py`'s.

`Sensing` receives the executor's `SkillContext` (`episode/context.py`: robot, mind, state
builder, camera, settings, tallies, trace) and the executor's record of found objects
(`found_sids`: known object id -> the detection's id, which the DT search and the strategies
write too). It owns the state its watch keeps between steps: whether the detector watches
(`watching`), the glimpses (`glimpses`, after `enable_glimpses`), confirmed detections the map
has no room for yet (`unplaced`), and objects seen while moving that the next step's outcome
reports (`seen_while_moving`, handed over by `take_seen`).
"""

from __future__ import annotations

import math

import numpy as np

from avs_planner.cp.task import Atom
from avs_planner.episode.context import SkillContext
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import SeenLike
from avs_planner.episode.viewcones import CameraModel
from conceptual_map.errors import MapError

Pose = tuple[float, float, float]


SAME_SPOT = 0.05  # m: a look around this near where a task's turn began is the turn's first

class Sensing:
    """Scans, looks and confirms for the executor (see the module's doc)."""

    def __init__(self, context: SkillContext, found_sids: dict[str, int],
                 watching: bool) -> None:
        self.context = context
        self.found_sids = found_sids
        self.watching = watching  # the detector looks for the target as the robot moves
        # where a task's next turn began (`harness/tasks.py`): a look around before the
        # robot has left that spot is skipped (`look_around`)
        self.resumed: tuple[float, float] | None = None
        self.kept = 0  # objects of labels the task also wants, made known (`_kept`)
        self.glimpses: Glimpses | None = None
        self.unplaced: list[SeenLike] = []  # confirmed, waiting for the map to give a room
        self.seen_while_moving: dict[str, set[Atom]] = {}

    def enable_glimpses(self) -> None:
        """Frames taken in passing become evidence (`episode/glimpses.py`)."""
        ctx = self.context
        self.glimpses = Glimpses(ctx.mind, ctx.camera, 1.0 - ctx.config.detector.false_negative,
                                 support_body=ctx.config.support_radius)

    def take_seen(self) -> dict[str, set[Atom]]:
        """The objects confirmed while moving since the last call, with their atoms (for the
        step's outcome); the record starts afresh."""
        seen, self.seen_while_moving = self.seen_while_moving, {}
        return seen

    def look_around(self) -> None:
        """Scan, turn half round, scan again: the first view of a place (the place map is
        updated once, after both scans). The detector watches in `look_headings` directions
        spread evenly over the turn (2: ahead and behind)."""
        ctx = self.context
        resumed, self.resumed = self.resumed, None
        if resumed is not None and math.dist(resumed, ctx.robot.pose[:2]) <= SAME_SPOT:
            # a task's next turn, the robot where the last one left it: the map is there,
            # and every frame of the turns before (driving, looking round, the DT's looks)
            # watched for this turn's label too
            ctx.emit("belief", looked_around="skipped: a task's next turn, whose label the "
                                             "frames so far watched for")
            return
        headings = max(2, ctx.config.look_headings)
        yaw = ctx.robot.pose[2]
        ctx.mind.integrate(ctx.robot.scan())
        kept = self.kept
        found = self.watch()
        half = headings // 2
        skipped: list[int] = []
        for k in range(1, headings):
            if (found is not None or self.kept > kept) and k > half:
                break  # the target (or a label the task also wants) is here: the map is done
            if found is not None and not ctx.builder.task.watch \
                    and ctx.mind.place_map.places:
                # the task's one target is known, in a room, and the map has places (the
                # robot's first look in a building it remembers, or a later one): the
                # report's verification looks from here, the way the robot faces. The scan
                # behind served a search that is over; turning there and back cost 5 s of
                # the 9 s a target seen from a remembered start took.
                if ctx.mind.place_map.current_place is None:
                    self.locate()
                break
            if self.unplaced and k < half:
                # the target is confirmed and waits only for the scan behind to give it a
                # room: turn straight there (a frame at each heading on the way cost a second
                # on every target seen in the first frame)
                continue
            heading = yaw + 2.0 * math.pi * k / headings
            # a heading before the half is on the way there (its turn is taken anyway); one
            # after it costs its turn too
            turn = 2.0 * math.pi / headings if k > half else 0.0
            if k != half and found is None and not self._worth_a_frame(heading, turn):
                # what this frame could show is worth less than its time; the scan behind
                # (the laser's half) is still taken
                skipped.append(k)
                continue
            ctx.robot.turn_to(heading)
            if k == half:
                found = self.sense([ctx.robot.pose], watch=True) or found
            elif found is None:
                found = self.watch()
        if skipped:
            ctx.emit("belief", look_skipped=[round(math.degrees(2.0 * math.pi * k / headings))
                                             for k in skipped],
                     reason="R x P(a frame there shows a wanted label) below its seconds")

    def _worth_a_frame(self, yaw: float, extra_turn: float) -> bool:
        """Whether a look-around frame at heading `yaw` (head ahead) is worth its time by
        the planner's own objective, c + R (1 - p): R x P(the frame shows a label the task
        wants) (`Glimpses.frame_value`) at least the seconds it costs, a frame and
        `extra_turn` radians of turning (as the loop's worth test prices a plan). Always
        True without `look_by_value`, glimpses or a body to price it with."""
        ctx = self.context
        body = ctx.mind.body
        if self.glimpses is None or not ctx.config.look_by_value or body is None:
            return True
        task = ctx.builder.task
        cmap = ctx.mind.cmap

        def p_room(label: str, room: str) -> float:
            try:
                return cmap.p_object_at(label, room)
            except (KeyError, MapError):
                return 1.0  # a label or room the map cannot price: look

        x, y, _ = ctx.robot.pose
        pose, tilt = (x, y, yaw), ahead_tilt(ctx.camera)
        labels = [task.target, *task.watch]
        cost = body.sensing_time + body.turn_time(extra_turn)
        floor = cost / ctx.config.miss_penalty
        for sighting in ctx.mind.remembered:
            # a spot the building's memory holds a wanted object at (P it is still there:
            # the sighting's weight) is a search of its own, which the map's P leaves out
            if sighting.label in labels and sighting.weight >= floor and self.glimpses.in_view(
                    np.array([sighting.position[:2]]), pose, 0.0, tilt,
                    sighting.position[2])[0]:
                return True
        return self.glimpses.frame_value(pose, 0.0, tilt, labels, p_room) >= floor

    def locate(self) -> None:
        """Integrate a scan from where the robot stands and put it at its place in the map,
        without a camera frame: in a building it remembers, the places are there already
        (the classifier's readings of them too), and a look at what is in view is the
        caller's."""
        self._emit_map_events(self._integrate([self.context.robot.pose]))
        self._record_pose()

    def _integrate(self, poses: list[Pose]) -> list:
        """A scan from `poses` into the mind's maps; the map events it made. What the
        building's placeholders led to so far, when that changed, goes to the trace (and how
        it corrects the placeholder model: `conceptual_map/conceptual/calibration.py`)."""
        ctx = self.context
        mind = ctx.mind
        resolved = mind.placeholder_outcomes.resolved
        events = mind.sense(ctx.robot.scan(), poses, ctx.robot.clock)
        if mind.placeholder_outcomes.resolved != resolved:
            ctx.emit("belief", placeholders=mind.cmap.calibration.summary())
        return events

    def _emit_map_events(self, events: list) -> None:
        """The trace's count of a scan's map events by kind and change (its `belief` event
        with `map_events`; the map snapshots follow it: `reporting/snapshots.py`)."""
        if events:
            kinds: dict[str, int] = {}
            for e in events:
                key = f"{e.kind.value}_{e.change.value}"
                kinds[key] = kinds.get(key, 0) + 1
            self.context.emit("belief", map_events=kinds)

    def sense(self, poses: list[Pose], watch: bool = False) -> KnownObject | None:
        """Integrate a scan from `poses`; the detector watches when asked or at a new place.
        Returns the target the watch confirmed, or one confirmed earlier that the scan placed
        in a room, if any."""
        ctx = self.context
        mind = ctx.mind
        before = mind.place_map.current_place
        events = self._integrate(poses)
        place = mind.place_map.current_place
        if place is not None and (place != before or place not in mind.classified):
            self.classify()
        seen = None
        if watch or (place is not None and place != before):
            seen = self.watch()
        if self.unplaced:
            # a target confirmed before the map had a room for it (the very first look) is
            # found now that the scan gave it one: the caller stops as for a watch's find
            seen = self.place_seen() or seen
        self._emit_map_events(events)
        self._record_pose()
        return seen

    def watch(self) -> KnownObject | None:
        """Keep the detector on while moving: look ahead for the target (a second frame must
        repeat a detection); a new confirmed target becomes a known object whose atoms reach
        the monitor with the next step's outcome (it may match a virtual object). The same
        frame looks for the supports the problem knows of: a new one, confirmed, becomes a
        known object too, and a frame that shows none of a label is evidence where it looked
        (`episode/glimpses.py`)."""
        if not self.watching:
            return None
        ctx = self.context
        task = ctx.builder.task
        label = task.target
        ctx.look(0.0, ahead_tilt(ctx.camera))
        # once a target is confirmed and only waits for the scan to give it a room, what the
        # frame shows of supports no longer matters: confirming a desk seen in passing took
        # a frame (a second) before the target could be reported
        glimpsing = self.glimpses is not None and not self.unplaced
        wanted = [label, *task.watch]
        labels = [*wanted, *ctx.builder.supports] if glimpsing else wanted
        frame = ctx.detect(labels)
        if glimpsing:
            self.glimpse(frame, labels)
        first = [s for s in frame if s.label == label]
        if not task.watch:
            if not first or self.known_near(first[0]):
                return None
        else:  # the first of the wanted labels (the target before the others) not known yet
            first = [s for lab in wanted for s in frame if s.label == lab
                     and not self.known_near(s) and not self._waiting_near(s)][:1]
            if not first:
                return None
        seen = first[0]
        again = self.confirm(seen)
        ctx.emit("observation", label=seen.label, detected=bool(again), watching=True,
                 position=[round(v, 2) for v in seen.position])
        if not again:
            return None
        self.unplaced.append(seen)
        return self.place_seen()

    def glimpse(self, frame: list[SeenLike], labels: list[str],
                head: tuple[float, float] | None = None) -> None:
        """What one frame (the head at `head`, pan and tilt; by default ahead, as the watch
        looks) says of `labels`: those it did not show are less likely where it looked;
        supports it shows (seen again in a second frame) become known. The tops of known
        supports count for the target only when the target is one of `labels`."""
        assert self.glimpses is not None
        ctx = self.context
        target = ctx.builder.task.target
        shown = {s.label for s in frame}
        unseen = [lab for lab in labels if lab not in shown]
        pan, tilt = head if head is not None else (0.0, ahead_tilt(ctx.camera))
        changed = self.glimpses.frame(ctx.robot.pose, pan, tilt, unseen,
                                      self.supports_of(target) if target in unseen else (),
                                      tops_label=target,
                                      shown={lab: [s.position for s in frame if s.label == lab]
                                             for lab in labels if lab in shown})
        if changed:
            ctx.emit("belief", glimpsed=changed)
        for seen in frame:
            if seen.label == target or self.known_near(seen):
                continue
            if seen.label in ctx.builder.task.watch:
                # a label the task also wants, seen in any frame (the DT's looks too): as
                # the watch does for the target, with its care (`confirm`'s defaults)
                if self._waiting_near(seen):
                    continue  # confirmed already, waiting for the map to give it a room
                again = self.confirm(seen)
                ctx.emit("observation", label=seen.label, detected=bool(again),
                         watching=True, position=[round(v, 2) for v in seen.position])
                if again:
                    self._keep_wanted(seen)
                continue
            if ctx.mind.room_at(seen.position[:2]) is None:
                continue
            if not self.confirm(seen, needed=1, frames=1, agree=ctx.config.agree[1]):
                continue
            obj = ctx.mind.add_object(seen.label, seen.position)
            self.seen_while_moving[obj.id] = {
                ("label-of", obj.id, seen.label), ("detected", obj.id),
                ("related", obj.id, "in", obj.room)}
            ctx.emit("observation", label=seen.label, detected=True, watching=True,
                     position=[round(v, 2) for v in seen.position], object=obj.id)

    def supports_of(self, label: str) -> list[str]:
        """Known objects `label` may lie on (the knowledge lists the relation)."""
        mind = self.context.mind
        listed = mind.cmap.knowledge.relation_lambda
        return [oid for oid, obj in mind.objects.items()
                if (label, "on", obj.label) in listed]

    def confirm(self, seen: SeenLike, needed: int | None = None, frames: int | None = None,
                agree: float | None = None) -> bool:
        """`needed` more frames (default `confirm_needed`) of up to `frames` (default
        `confirm_frames`) see the label again within `agree` metres. Without the DT's
        belief, a report rests on this: a phantom (5% of frames, anywhere in view) that
        repeats twice at the same spot is practically never seen, while a real object missed
        in 1 frame of 5 still passes 9 times in 10. One short with some frame agreeing is
        ambiguous: up to `confirm_extra` more frames are taken (once)."""
        cfg = self.context.config
        agree = cfg.agree[0] if agree is None else agree
        needed = cfg.confirm_needed if needed is None else needed
        frames = cfg.confirm_frames if frames is None else frames
        hits = k = 0
        extended = False
        while k < frames:
            if any(s.label == seen.label and math.dist(s.position, seen.position) <= agree
                   for s in self.context.detect([seen.label])):
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

    def place_seen(self) -> KnownObject | None:
        """Confirmed detections become known objects once the place map has a room for them
        (the very first look comes before the first place)."""
        ctx = self.context
        obj = None
        for seen in list(self.unplaced):
            room = ctx.mind.room_at(seen.position[:2])
            if room is None and (seen.label == ctx.builder.task.target
                                 or seen.label in ctx.builder.task.watch):
                # a target seen through a door is reported from here; its room (evidence
                # about the room's category) is the nearest known one until it is entered
                room = ctx.mind.nearest_room(seen.position[:2])
            if room is None:
                continue
            self.unplaced.remove(seen)
            found = ctx.mind.add_object(seen.label, seen.position, room=room)
            self.found_sids[found.id] = seen.id
            if seen.label != ctx.builder.task.target:
                self._kept(seen, found)
                continue
            obj = found
            self.seen_while_moving[obj.id] = {
                ("label-of", obj.id, seen.label), ("detected", obj.id),
                ("related", obj.id, "in", obj.room)}
        return obj

    def _keep_wanted(self, seen: SeenLike) -> None:
        """A confirmed detection of a label the task also wants becomes a known object in
        the room it stands in, else the nearest known one (as a target seen through a door)."""
        mind = self.context.mind
        room = mind.room_at(seen.position[:2]) or mind.nearest_room(seen.position[:2])
        if room is None:
            self.unplaced.append(seen)
            return
        obj = mind.add_object(seen.label, seen.position, room=room)
        self.found_sids[obj.id] = seen.id
        self._kept(seen, obj)

    def _kept(self, seen: SeenLike, obj: KnownObject) -> None:
        """A label the task also wants (`SearchTask.watch`) is known now: reported in its
        own turn (the planner's problem of this turn has no such label)."""
        self.kept += 1
        self.context.emit("observation", label=seen.label, detected=True, watching=True,
                          position=[round(v, 2) for v in seen.position], object=obj.id,
                          wanted=True)

    def _waiting_near(self, seen: SeenLike) -> bool:
        """A confirmed detection of the same label near `seen` waits for a room (`unplaced`):
        confirming it again would make one object two."""
        reach = self.context.config.same_object
        return any(u.label == seen.label and math.dist(u.position[:2], seen.position[:2])
                   <= reach for u in self.unplaced)

    def known_near(self, seen: SeenLike) -> bool:
        """A detection of an object the mind already knows (same label, within
        `same_object` metres)."""
        reach = self.context.config.same_object
        return any(obj.label == seen.label and math.dist(obj.position[:2], seen.position[:2])
                   <= reach for obj in self.context.mind.objects.values())

    def classify(self) -> None:
        """Ask the place classifier, unless the robot stands within `doorway_clearance` m of
        a door (it would see the room beyond and credit it to this place); a reading that
        cannot be used is a warning in the trace, never dropped silently."""
        ctx = self.context
        if ctx.mind.near_door(ctx.robot.pose[:2], ctx.config.doorway_clearance):
            return
        observed = ctx.robot.classify_place()
        if observed is None:
            ctx.emit("warning", source="place_classifier", detail="no reading here")
            return
        unused = ctx.mind.observe_appearance(observed)
        if unused is not None:
            ctx.emit("warning", source="place_classifier", observed=observed, detail=unused)

    def _record_pose(self) -> None:
        """Append the robot's pose and its room's most likely category (if any) to the
        path the tallies keep."""
        ctx = self.context
        x, y, yaw = ctx.robot.pose
        room = ctx.mind.room_at((x, y))
        category = ""
        if room is not None and ctx.mind.cmap.graph.has_room(room):
            belief = ctx.mind.cmap.room_category(room)
            category = max(belief, key=belief.get)
        ctx.stats.path.append((x, y, yaw, category))


def ahead_tilt(camera: CameraModel) -> float:
    """The head's tilt while watching: towards support height `look_distance` m ahead."""
    return -math.atan2(camera.height - camera.support_height, camera.look_distance)
