"""SEARCHFOROBJECT: a closed-loop DT session over the view cones, against the robot's detector.

MOVE actions drive to a cone's pose and point the head; PROCESSVIEWCONE looks twice (a
detection counts when both frames agree; when they split, a third frame decides); a
confirmation becomes a known object, every search (confirmed or rejected) thins the conceptual
map's unseen count there by the coverage of the cones looked through.

The session is the DT of the active visual search paper (Göbelbecker et al., §2): its MOVE
costs are the robot's own driving times along the paths it would drive (`PathLengths`:
`plan_path` on its grid, as the executor drives, never straight lines through walls), computed
once per session; cones no path reaches are left out. Its terminal penalties are the CP's goal
reward R (`ExecutorConfig.miss_penalty`, which the switching strategy sets from
`LoopConfig.reward`).
A search of a support looks on it and in it, as the knowledge lists the label there
(`viewcones.support_relations`).

`ViewConeSearch` is one SEARCHFOROBJECT, a skill of the executor (`Executor.view_cone_search`
makes it): it receives the executor's `SkillContext` (`episode/context.py`: robot, mind, state
builder, settings, tallies, trace, seed), the driving skill (`Driver`: drives to cones, prices
travel with its paths), the sensing skill (`Sensing`: glimpses, known objects, supports), the
cone sets (`ConeSets`: the cones to search), the record of found objects (`found_sids`) and two
hooks: `on_look` before each look (e.g. depth) and `on_session` with the running DT session
(for observers).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace

from avs_planner.dt import (
    DTRewards,
    DTSession,
    DTStatus,
    LabelStatus,
    LabelTarget,
    MultiLabelSession,
    SearchBudget,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.domain import REJECT, ActionKind
from avs_planner.dt.multi.domain import MultiAction
from avs_planner.dt.session import DTResult
from avs_planner.episode.cone_sets import ConeSets
from avs_planner.episode.context import SkillContext
from avs_planner.episode.driving import TARGET_SEEN, Driver, Point
from avs_planner.episode.mind import Mind
from avs_planner.episode.outcome import SeenLike, StepOutcome, StepStatus
from avs_planner.episode.sensing import Sensing
from avs_planner.episode.viewcones import (
    ConeSet,
    p_at_support,
    support_relations,
    support_spaces,
)
from conceptual_map.errors import MapError
from conceptual_map.metric import plan_path
from conceptual_map.metric.path_planning import PathResult


class ViewConeSearch:
    """One SEARCHFOROBJECT for `label` `relation` `location` (see the module's doc)."""

    def __init__(self, context: SkillContext, driver: Driver, sensing: Sensing,
                 cone_sets: ConeSets, found_sids: dict[str, int], label: str, relation: str,
                 location: str, on_look: Callable[[], None] | None = None,
                 on_session: Callable[[DTSession], None] | None = None) -> None:
        self.context, self.driver, self.sensing = context, driver, sensing
        self.cone_sets, self.found_sids = cone_sets, found_sids
        self.label, self.relation, self.location = label, relation, location
        self.on_look, self.on_session = on_look, on_session
        self.head: tuple[float, float] = (0.0, 0.0)  # where the camera points (pan, tilt)
        # the target seen by a look's frame outside the searched location (`_detect_once`)
        self.elsewhere: SeenLike | None = None

    def run(self) -> StepOutcome:
        ctx, robot, cfg = self.context, self.context.robot, self.context.config
        label, relation, location = self.label, self.relation, self.location
        made = self.cone_sets.now(label, relation, location)
        if made is None or not made.cones:
            return StepOutcome(StepStatus.FAILED, "no view cones for this search")
        made, travel = self._reachable(made)
        if not made.cones:
            return StepOutcome(StepStatus.FAILED, "no view cone of this search is reachable")
        ctx.stats.dt_calls += 1
        reward = cfg.miss_penalty  # R, the CP's goal reward (`LoopConfig.reward`)
        others = self._watched(made)
        if others:
            return self._run_several(made, travel, others)
        session = DTSession(made.cones, cfg.detector, robot.pose,
                            travel_costs=travel, policy=cfg.dt_policy,
                            budget=SearchBudget(num_sims=cfg.dt_sims),
                            rewards=DTRewards(reward, reward),
                            seed=ctx.seed + ctx.stats.dt_calls)
        if self.on_session is not None:  # the running session, for observers (the recorder)
            self.on_session(session)
        interrupted = False
        while True:
            action = session.next_action()
            if session.finished:
                break
            cone = session.cone(action)
            if action.kind is ActionKind.MOVE:
                if not self._arrive(cone):
                    # the watch confirmed the target on the way to this cone: stop here
                    # (the looks so far still count) and let the planner report it
                    session.update(REJECT)
                    interrupted = True
                    break
                session.update(action)
                continue
            match = self._look(label, relation, location)
            session.update(action, match is not None, detection=match)
            if match is None and self._confirmed_elsewhere():
                # the look saw the target beside the location searched, and it held: stop
                # here as the watch does on the way (the looks so far still count)
                session.update(REJECT)
                interrupted = True
                break
        result = session.result
        ctx.stats.dt_decisions.extend(result.decision_times_s)
        ctx.emit("dt", label=label, relation=relation, location=location,
                 result=result.status.value, probability=round(result.probability, 4),
                 steps=len(result.trace), cones=len(made.cones))
        return self._conclude(result, label, relation, location, made, interrupted)

    def _arrive(self, cone: ViewCone) -> bool:
        """MOVE to a cone: drive to its pose, turn, point the head (and set the torso); False
        when the watch confirmed the target on the way (the robot stops there)."""
        robot = self.context.robot
        if self.driver.drive_to(cone.pose[:2]).detail == TARGET_SEEN:
            return False
        robot.turn_to(cone.pose[2])
        self.head = cone.head or (0.0, 0.0)
        self.context.look(*self.head)
        if cone.torso is not None:
            robot.set_torso(cone.torso)
        return True

    # ---- a task of several objects: one session over this label and the others it wants ----

    def _watched(self, made: ConeSet) -> list[tuple[str, tuple[float, ...]]]:
        """The labels the task also wants (`SearchTask.watch`) that may be in this search's
        cones, with P(label in cone i): the map's P(label at the location) spread over the
        cones as this label's cones share its own (the cones cover the same space for every
        label; a support only where the knowledge puts the label on or in it). Labels below
        the planner's threshold are left to the frames' glimpses."""
        ctx = self.context
        builder, mind = ctx.builder, ctx.mind
        if not builder.task.watch or made.probability <= 0.0:
            return []
        out = []
        for label in builder.task.watch:
            try:
                if self.relation == "on":
                    support = mind.objects[self.location]
                    if not support_relations(mind, label, support.label):
                        continue
                    p = p_at_support(mind, label, self.location)
                else:
                    p = mind.cmap.p_object_at(label, self.location)
            except (KeyError, MapError):
                continue
            scale = min(1.0, p) / made.probability
            probs = tuple(min(1.0, c.probability * scale) for c in made.cones)
            if sum(probs) >= builder.config.min_probability:
                total = sum(probs)
                out.append((label, probs if total <= 1.0 else tuple(q / total for q in probs)))
        return out

    def _run_several(self, made: ConeSet, travel: TravelCosts,
                     others: list[tuple[str, tuple[float, ...]]]) -> StepOutcome:
        """One DT session over this search's label and the others the task wants
        (`avs_planner.dt.multi`: a look serves every label, each is confirmed or rejected on
        its own): a confirmed other label becomes a known object (the task reports it in its
        own turn), every label's unseen count is thinned by the looks, and this label's result
        concludes the step as a one-label session's would."""
        ctx, robot, cfg = self.context, self.context.robot, self.context.config
        label = self.label
        reward = cfg.miss_penalty
        rewards = DTRewards(reward, reward)
        mass = sum(c.probability for c in made.cones)
        own = tuple(c.probability / mass * min(1.0, mass) for c in made.cones) if mass > 0 \
            else tuple(0.0 for _ in made.cones)
        targets = [LabelTarget(label, own, cfg.detector, rewards)]
        targets += [LabelTarget(w, probs, cfg.detector, rewards) for w, probs in others]
        session = MultiLabelSession(made.cones, targets, robot.pose, travel_costs=travel,
                                    mode=ctx.builder.task.mode)
        interrupted = False
        while True:
            action = session.next_action()
            if session.finished:
                break
            if action.kind is ActionKind.CONFIRM:
                if action.label != label:
                    self._keep_other(session, action)
                continue
            if action.kind is ActionKind.REJECT:
                continue
            cone = session.cone(action)
            assert cone is not None
            if action.kind is ActionKind.MOVE:
                if not self._arrive(cone):
                    interrupted = True  # as a one-label session: the planner reports it
                    break
                session.update(action)
                continue
            open_ = [lab for lab, r in session.label_results().items()
                     if r.status is LabelStatus.OPEN]
            seen, detections = self._look_several(open_)
            session.update(action, seen, detections)
        return self._conclude_several(session, made, interrupted)

    def _look_several(self, labels: list[str]) -> tuple[dict[str, bool], dict[str, SeenLike]]:
        """PROCESSVIEWCONE for several labels: one frame asks for all (and the supports, as
        a one-label look's first frame does); each label detected in the searched location
        is looked at again as `_look` does, and counts when a frame agrees."""
        ctx = self.context
        ctx.stats.views += 1
        if self.on_look is not None:
            self.on_look()
        also = [a for a in self._also_for(self.label) if a not in labels] \
            if self.label in labels else []
        frame = ctx.detect([*labels, *also])
        if also:  # the session's own labels are its to confirm and thin, not the glimpses'
            self.sensing.glimpse([s for s in frame if s.label not in labels], also, self.head)
        seen: dict[str, bool] = {}
        detections: dict[str, SeenLike] = {}
        frames = 1 + (1 if ctx.config.dt_tiebreak else 0)
        for label in labels:
            match = next((s for s in frame if s.label == label
                          and self._inside(s, self.relation, self.location)), None)
            agreed = False
            if match is not None:
                agree = ctx.config.agree[0]
                for _ in range(frames):
                    again = next((s for s in ctx.detect([label]) if s.label == label), None)
                    agreed = again is not None and \
                        math.dist(again.position, match.position) <= agree
                    if agreed:
                        break
            elif label == self.label:
                self._glimpse_tops(label, self.relation, self.location)
            ctx.emit("observation", label=label, detected=agreed,
                     **({"position": [round(v, 2) for v in match.position]}
                        if match is not None else {}))
            seen[label] = agreed
            if agreed:
                detections[label] = match
        return seen, detections

    def _keep_other(self, session: MultiLabelSession, action: MultiAction) -> None:
        """The session confirmed a label the task also wants: a known object now (its turn
        reports it), unless the mind knows one there already."""
        result = session.label_results()[action.label]
        seen = result.detection
        if seen is None or self.sensing.known_near(seen):
            return
        mind = self.context.mind
        support = self.location if self.relation == "on" else None
        room = None if support else (mind.room_at(seen.position[:2])
                                     or mind.nearest_room(seen.position[:2]))
        if support is None and room is None:
            return
        obj = mind.add_object(seen.label, seen.position, support, room=room)
        self.found_sids[obj.id] = seen.id
        self.context.emit("observation", label=seen.label, detected=True, object=obj.id,
                          position=[round(v, 2) for v in seen.position], wanted=True)

    def _conclude_several(self, session: MultiLabelSession, made: ConeSet,
                          interrupted: bool) -> StepOutcome:
        """This label's part as a one-label session's result (`_conclude`), and the other
        labels' unseen counts thinned by the same looks."""
        ctx = self.context
        label, relation, location = self.label, self.relation, self.location
        result = session.result
        results = result.labels if result is not None else session.label_results()
        steps = tuple(step for step in (result.trace if result is not None else ())
                      if step.action.kind in (ActionKind.MOVE, ActionKind.PROCESS_VIEW_CONE))
        times = result.decision_times_s if result is not None else ()
        mine = results[label]
        status = DTStatus.CONFIRMED if mine.status is LabelStatus.CONFIRMED \
            else DTStatus.REJECTED
        ctx.stats.dt_decisions.extend(times)
        ctx.emit("dt", label=label, relation=relation, location=location,
                 result=status.value, probability=round(mine.probability, 4),
                 steps=len(steps), cones=len(made.cones),
                 labels={lab: r.status.value for lab, r in results.items() if lab != label})
        looks: dict[int, int] = {}
        for step in steps:
            if step.action.kind is ActionKind.PROCESS_VIEW_CONE:
                looks[step.action.cone] = looks.get(step.action.cone, 0) + 1
        coverage = self._coverage(made, looks, label, relation, location)
        if coverage > 0.0:
            for other in results:
                if other != label:
                    self._searched(other, relation, location, coverage)
        single = DTResult(status, mine.probability, result.cost if result else 0.0, steps,
                          mine.cone_id, mine.detection, None, tuple(times))
        return self._conclude(single, label, relation, location, made, interrupted)

    def _reachable(self, made: ConeSet) -> tuple[ConeSet, TravelCosts]:
        """The cones the robot has a path to, and the DT's travel costs between them: driving
        time along the robot's paths (`PathLengths`) plus the turn. A cone no path reaches
        from the robot is left out (its share of the location stays unsearched); two cones
        with no path between them are priced through the robot's pose."""
        lengths = PathLengths(self.context.mind, self.driver.squeeze)
        here = self.context.robot.pose
        keep = [c for c in made.cones if math.isfinite(lengths(here[:2], c.pose[:2]))]
        if len(keep) < len(made.cones):
            self.context.emit("belief", unreachable_cones=[c.id for c in made.cones
                                                           if c not in keep])
            made = replace(made, cones=tuple(keep))
        return made, travel_costs(here, made.cones, lengths, *self._speeds())

    def _speeds(self) -> tuple[float, float]:
        """(m/s, rad/s) the robot's body drives and turns at (the time model's defaults
        without a body)."""
        body = self.context.mind.body
        return (body.linear_speed, body.angular_speed) if body is not None else (0.5, 1.0)

    def _look(self, label: str, relation: str, location: str) -> SeenLike | None:
        """PROCESSVIEWCONE: a detection in the searched location, seen twice. When the
        second frame does not repeat the first (`ExecutorConfig.dt_tiebreak`), a third frame
        decides: a real object 3.6 m away is missed or misplaced beyond the agreement distance
        in about 30% of frames, so a real target seen once was called absent from its cone
        30% of the time and the DT went on to other cones with the belief there thinned; a
        phantom (5% of frames, anywhere in view) is rarely repeated at the same spot by
        either frame."""
        ctx = self.context
        ctx.stats.views += 1
        if self.on_look is not None:
            self.on_look()
        self.elsewhere = None
        match = self._detect_once(label, relation, location, self._also_for(label))
        if match is None:
            ctx.emit("observation", label=label, detected=False)
            self._glimpse_tops(label, relation, location)
            return None
        agree = ctx.config.agree[0 if label == ctx.builder.task.target else 1]
        frames = 1 + (1 if ctx.config.dt_tiebreak else 0)
        agreed = False
        for _ in range(frames):
            again = self._detect_once(label, relation, location)
            agreed = again is not None and math.dist(again.position, match.position) <= agree
            if agreed:
                break
        ctx.emit("observation", label=label, detected=agreed,
                 position=[round(v, 2) for v in match.position])
        return match if agreed else None

    def _confirmed_elsewhere(self) -> bool:
        """A look's first frame showed the target outside the location searched (on the
        next support, across the room): confirmed by more frames as the watch confirms what
        it sees, it becomes a known object (`Sensing.place_seen`) and the search stops for
        the planner to report it. Before, such a detection only counted for the DT's belief
        about the location, and was dropped: a book seen from a view cone on the shelf beside
        the one searched was never looked at again, and the robot gave up (development
        office 345)."""
        seen, self.elsewhere = self.elsewhere, None
        if seen is None:
            return False
        again = self.sensing.confirm(seen)
        self.context.emit("observation", label=seen.label, detected=again, elsewhere=True,
                          position=[round(v, 2) for v in seen.position])
        if not again:
            return False
        self.sensing.unplaced.append(seen)
        return self.sensing.place_seen() is not None

    def _glimpse_tops(self, label: str, relation: str, location: str) -> None:
        """A look for the target that saw none also looked at the tops of other known
        supports in view (`episode/glimpses.py`); the searched location itself is this
        search's own evidence (`Mind.searched`)."""
        glimpses = self.sensing.glimpses
        if glimpses is None or label != self.context.builder.task.target:
            return
        supports = [o for o in self.sensing.supports_of(label)
                    if not (relation == "on" and o == location)]
        glimpses.frame(self.context.robot.pose, self.head[0], self.head[1], [], supports,
                       tops_label=label)

    def _also_for(self, label: str) -> list[str]:
        """The labels the first frame of a look for the target also looks for: the supports
        the problem knows of, as the watch's frames do (`Sensing.glimpse`). A support it
        shows becomes a known object; one it does not show is less likely in the cells the
        frame had in view with a free line of sight. Without this, a room the DT had looked
        through kept most of its prior count of desks not found yet, each with its share
        of the target, and the stopping rule went on searching rooms already searched.
        (The cones' coverage of the target's location is no measure of that: it does not
        know what the furniture hides, and a kitchen whose table stands behind a fridge
        row lost its tables and counters to it, and with them its category.)"""
        builder = self.context.builder
        if self.sensing.glimpses is None or label != builder.task.target:
            return []
        # the labels the task also wants: the frame is evidence where it shows none of
        # them (a confirmed one is the watch's to find, as the robot drives on)
        return [*builder.task.watch, *(s for s in builder.supports if s != label)]

    def _detect_once(self, label: str, relation: str, location: str,
                     also: Sequence[str] = ()) -> SeenLike | None:
        frame = self.context.detect([label, *also])
        if also:
            self.sensing.glimpse(frame, list(also), self.head)
        seen = [s for s in frame if s.label == label]
        matches = [s for s in seen if self._inside(s, relation, location)]
        if not matches and label == self.context.builder.task.target:
            self.elsewhere = next((s for s in seen if not self.sensing.known_near(s)), None)
        for s in seen:
            self.context.stats.detections.append((s.position[0], s.position[1], label,
                                                  s in matches))
        return matches[0] if matches else None

    def _inside(self, seen: SeenLike, relation: str, location: str) -> bool:
        mind, cfg = self.context.mind, self.context.config
        if relation == "on":  # a support: on its top, or inside it where the knowledge
            support = mind.objects[location]  # puts the label
            top = 2.0 * support.position[2]
            low, high = cfg.above_support
            relations = support_relations(mind, seen.label, support.label)
            if "in" in relations:
                low = -top  # down to the floor: a cup in a shelf
            if "on" not in relations:
                high = 0.0
            reach = cfg.support_radius
            near = math.dist(seen.position[:2], support.position[:2]) <= reach
            if near and self.context.builder.task.exclude and self.sensing.known_near(seen):
                return False  # one reported before: the task wants another one
            return near and top + low <= seen.position[2] <= top + high
        if mind.room_at(seen.position[:2]) != location:
            return False
        return not self.sensing.known_near(seen)  # not a desk it found before

    def _searched(self, label: str, relation: str, location: str, coverage: float) -> None:
        """The looks thin `label`'s unseen count at the location: a room, or every space of a
        support the search looked at (on it, in it)."""
        mind = self.context.mind
        if relation != "on":
            mind.searched(label, relation, location, coverage, 1.0)
            return
        for space in support_spaces(mind, label, location):
            mind.cmap.observe_search(label, space, min(1.0, coverage), 1.0)

    def _coverage(self, made: ConeSet, looks: dict[int, int], label: str, relation: str,
                  location: str) -> float:
        """The share of the location's objects the looks would have seen. On the top of a
        support (where the knowledge puts `label` on it only), from what each look had of the
        top in view (`Glimpses.top_share`), as frames in passing count, when the cones are
        the 2D ones round it; else, or when no look had the top in view by that model, from
        the cones' shares of the location (`looked_share`)."""
        mind = self.context.mind
        glimpses, obj = self.sensing.glimpses, mind.objects.get(location)
        if relation == "on" and looks and glimpses is not None and obj is not None \
                and self.cone_sets.support_views is None \
                and support_relations(mind, label, obj.label) == ("on",):
            share = glimpses.top_share(location, [
                (made.cones[i].pose, *(made.cones[i].head or (0.0, 0.0)), k)
                for i, k in looks.items()])
            if share:
                return share
        return looked_share(made, looks, 1.0 - self.context.config.detector.false_negative)

    def _conclude(self, result: DTResult, label: str, relation: str, location: str,
                  made: ConeSet, interrupted: bool = False) -> StepOutcome:
        builder = self.context.builder
        looks: dict[int, int] = {}
        for step in result.trace:
            if step.action.kind is not ActionKind.MOVE:
                looks[step.action.cone] = looks.get(step.action.cone, 0) + 1
        coverage = self._coverage(made, looks, label, relation, location)
        if result.status is DTStatus.CONFIRMED and result.detection is not None:
            seen = result.detection
            support = location if relation == "on" else None
            obj = self.context.mind.add_object(label, seen.position, support)
            self.found_sids[obj.id] = seen.id
            if coverage > 0.0:
                # Poisson thinning: whatever was found, the cones looked through leave
                # Poisson(lambda (1 - share seen)) of `label` unseen there, so a second
                # desk stays as likely as before only in the part not looked at
                self._searched(label, relation, location, coverage)
            atoms = {("label-of", obj.id, label), ("detected", obj.id),
                     ("related", obj.id, relation, location)}
            return StepOutcome(StepStatus.DONE, f"confirmed {obj.id}", {obj.id: atoms})
        if coverage > 0.0:
            self._searched(label, relation, location, coverage)
        if interrupted:  # not a failed search: it stopped because the target turned up
            return StepOutcome(StepStatus.DONE, TARGET_SEEN)
        if not looks:
            # the DT, on its belief, found no look there worth its cost: asked again from
            # the same state it would decide the same, in no time, and the loop took the
            # repeat for a livelock and gave up with everything else still to search
            # (generated office 300, book: at 667 s, P left = 1). Settled for the planner.
            builder.cannot_search(label, relation, location)
            return StepOutcome(StepStatus.DONE, "rejected without looking")
        if relation == "on":
            key = (label, location)
            builder.failed_on[key] = builder.failed_on.get(key, 0) + 1
        else:
            key = (label, location)
            builder.failed_in[key] = builder.failed_in.get(key, 0) + 1
        return StepOutcome(StepStatus.DONE, "rejected")


def looked_share(made: ConeSet, looks: dict[int, int], p_detect: float) -> float:
    """The share of the location's objects that `looks` (cone index -> looks into it) would
    have seen: the cones cover `made.coverage` of the location between them, each cone its
    probability's part of that; a cone looked into k times misses with (1 - p_detect)^k.

    The cone makers differ in what their probabilities add up to (a room's cones to
    P(ObjectAt) x coverage, a support's to P(ObjectAt)), so each cone's part is its
    probability over the cones' sum, never over `made.probability`: divided by that, a
    room's coverage counted twice (a search over 0.8 of a room thinned it as if over 0.64)."""
    mass = sum(c.probability for c in made.cones)
    if mass <= 0.0:
        return 0.0
    seen = sum(made.cones[i].probability * (1.0 - (1.0 - p_detect) ** k)
               for i, k in looks.items())
    return seen / mass * made.coverage


class PathLengths:
    """Lengths (m) of the paths the robot would drive between two points, as the driving
    skill plans them (`plan_path` on the mind's grid keeping its planning radius, else
    `squeeze`, the driver's: a slimmer margin, then unknown cells); inf where there is none.
    Memoised: one instance serves one DT session (the grid does not change while its costs
    are made)."""

    def __init__(self, mind: Mind, squeeze: Callable[[Point, Point], PathResult]) -> None:
        self.mind, self.squeeze = mind, squeeze
        self._memo: dict[tuple[tuple[float, float], tuple[float, float]], float] = {}

    def __call__(self, a: Sequence[float], b: Sequence[float]) -> float:
        pa, pb = (round(a[0], 3), round(a[1], 3)), (round(b[0], 3), round(b[1], 3))
        key = (pa, pb) if pa <= pb else (pb, pa)
        if key not in self._memo:
            self._memo[key] = self._length(*key)
        return self._memo[key]

    def _length(self, a: tuple[float, float], b: tuple[float, float]) -> float:
        if math.dist(a, b) < 1e-9:
            return 0.0
        mind = self.mind
        try:
            path = plan_path(mind.grid, a, b, mind.config.robot_radius)
        except MapError:
            path = None
        if path is None or not path.found:
            path = self.squeeze(a, b)
        return path.length if path.found else math.inf


def travel_costs(start: Sequence[float], cones: Sequence[ViewCone], length: PathLengths,
                 speed: float, turn_speed: float) -> TravelCosts:
    """The DT's MOVE costs (s): driving time along `length` plus the turn to the cone's
    heading; a pair of cones with no path between them is priced through `start` (both are
    reachable from there)."""
    def cost(a: Sequence[float], b: Sequence[float], metres: float) -> float:
        return metres / speed + abs(math.remainder(b[2] - a[2], math.tau)) / turn_speed

    poses = [c.pose for c in cones]
    from_start = [length(start[:2], p[:2]) for p in poses]
    rows = []
    for i, a in enumerate(poses):
        row = []
        for j, b in enumerate(poses):
            metres = length(a[:2], b[:2])
            if not math.isfinite(metres):
                metres = from_start[i] + from_start[j]
            row.append(cost(a, b, metres))
        rows.append(row)
    return TravelCosts.from_lists([cost(start, p, m) for p, m in zip(poses, from_start,
                                                                      strict=True)], rows)
