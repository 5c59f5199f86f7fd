"""QSR indirect search as three strategies on one loop, after Kunze, Kumar and Hawes, "Indirect
Object Search based on Qualitative Spatial Relations".

`qsr`, `supporting-planes` and `random` differ only in the density view selection uses (the QSR
mixture over the supporting planes, uniform over them, a random one of the sampled poses). The
loop follows the QSR paper's control program: a search monitor (found? more than `abort_s` simulated
seconds of search? then stop), the search method (Algorithm 1: `select_view`), navigation to
the chosen pose, and perception with the best frustums there (pan/tilt, a depth frame into the
3D map, detection confirmed by a second frame). Voxels a frustum has covered lose density
(`seen_weight` per look), so the next selection looks elsewhere.

The QSR paper (Kunze et al.) starts with its 2D and 3D maps and the landmarks' poses given. Here
the robot gets them itself first, in a *survey* that does not look for the target: it looks all
round at its start and at a few frontier stops, integrating laser scans, depth frames (the
mind's voxel map) and detections of the knowledge's landmark labels. A landmark is a label
detected at least twice (in two frames) at positions within the executor's agreement distance;
its position is the mean of those detections. Its *facing* (the direction of its intrinsic
front) is an assumption written down here and in `conceptual_map/qsr/README.md`: a landmark
faces the open side, the mean direction from it to the cells of the 2D map where the robot can
stand within `OPEN_SIDE_RADIUS` (desks stand against walls or each other and are used from the
free side; monitors and keyboards on them face the same way). The search monitor's clock starts
when the survey ends (the QSR paper's time is search time with known maps); summaries carry both
times.

After a found object, the knowledge learns from it (`learn_from_observation` with the surveyed
landmarks) for the rest of the episode. With an experience store in the search context
(`SearchContext.experience`, an episode's `experience` file), the search starts from the
descriptions earlier episodes learned, and what it learns goes back there when the episode
ends well (`conceptual_map/knowledge/experience.py`). Nothing is kept in the process: an
episode's result depends only on its inputs (a service worker or a campaign process runs many
episodes, in any order).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import Outcome, SearchResult, StepStatus
from avs_planner.qsr import (
    LandmarkTracker,
    ScoredPose,
    ViewMethod,
    ViewOptions,
    in_frustums,
    landmarks_from,
    line_of_sight,
    pose_rates,
    rank_frustums,
    score_poses,
    select_view,
)
from avs_planner.strategies.baselines import explore
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.looking import (
    LOOK_DISTANCE,
    SUPPORT_HEIGHT,
    _confirm,
    known_target,
)
from conceptual_map.qsr import (
    Landmark,
    QsrKnowledge,
    SupportingPlanes,
    build_mixture,
    extract_supporting_planes,
    learn_from_observation,
    load_qsr,
)

MAX_DRIVE_FAILURES = 5  # selected poses the robot could not reach before giving up


def run_qsr(ctx: SearchContext) -> SearchResult:
    return QsrSearch(ctx, ViewMethod.QSR).run()


def run_supporting_planes(ctx: SearchContext) -> SearchResult:
    return QsrSearch(ctx, ViewMethod.SUPPORTING_PLANES).run()


def run_random(ctx: SearchContext) -> SearchResult:
    return QsrSearch(ctx, ViewMethod.RANDOM).run()


# ---- the search ----------------------------------------------------------------------------


@dataclass
class _Look:
    camera: np.ndarray
    heading: float
    tilt: float


class QsrSearch:
    """One search with one method: survey, then the monitor / select / drive / perceive loop."""

    def __init__(self, ctx: SearchContext, method: ViewMethod):
        self.ctx, self.method, self.opt = ctx, method, ctx.options
        self.rng = np.random.default_rng(ctx.executor.seed)
        self.looks: list[_Look] = []
        self.poses = 0
        self.here: ScoredPose | None = None  # where the robot looked last, if it has not moved
        self.looks_here = 0  # looks made from the current pose
        self.survey_s = 0.0
        self.search_start = 0.0
        self.landmarks: list[Landmark] = []
        self.knowledge, self.knowledge_from = self._knowledge()
        self.mixture = None
        self.result = SearchResult(Outcome.GAVE_UP, "")

    # -- knowledge --

    def _knowledge(self) -> tuple[QsrKnowledge, str]:
        """The task's descriptions; else the default knowledge with what the experience
        store learned, when the episode has one; else the default knowledge."""
        ctx = self.ctx
        if ctx.qsr is not None:
            return ctx.qsr, "task"
        if ctx.experience is not None:
            return ctx.experience.qsr_knowledge(load_qsr()), "experience"
        return load_qsr(), "default"

    # -- the loop --

    def run(self) -> SearchResult:
        ctx = self.ctx
        start = ctx.robot.clock
        watching = getattr(ctx.executor, "watching", False)
        ctx.executor.watching = False  # the survey does not look for the target
        try:
            self.survey()
        finally:
            ctx.executor.watching = watching and self.opt["watch"]
        self.survey_s = ctx.robot.clock - start
        self.search_start = ctx.robot.clock
        self._prepare_mixture()
        failures = 0
        while True:
            stop = ctx.budget_spent()
            if stop:
                return self._end(Outcome.TIMEOUT, stop)
            if self.search_time() >= self.opt["abort_s"]:
                return self._end(Outcome.GAVE_UP, f"search monitor: nothing found in "
                                                  f"{self.opt['abort_s']:g} s of search")
            if self.poses >= self.opt["max_poses"]:
                return self._end(Outcome.GAVE_UP, f"{self.poses} view poses searched")
            planes = extract_supporting_planes(ctx.mind.voxels)
            if len(planes) == 0:
                return self._end(Outcome.GAVE_UP, "no supporting planes perceived")
            density = self.density(planes)
            pose = ctx.robot.pose
            view = select_view(ctx.mind.grid, planes.points, density, ctx.body, self.method,
                               rng=self.rng, options=ViewOptions(
                                   n_poses=self.opt["n_poses"],
                                   pan_sweep=math.radians(self.opt["pan_sweep_deg"]),
                                   start=pose[:2], occlusion=ctx.mind.voxels))  # fmt: skip
            if not view.selected:
                return self._end(Outcome.GAVE_UP, f"view selection: {view.status.value}")
            best = view.best  # eq. 2's argmax (random: a random one)
            if self.relooks():
                best = self.choose(view.poses, self.stay_pose(planes, density))
                if best is self.here:
                    if self.look_again(planes, density):
                        return self._found(self.result.found)
                    continue
            elif self.opt["utility"] == "rate" and self.method is not ViewMethod.RANDOM:
                best = self.choose(view.poses)
            ctx.trace.emit("action", action=f"(view-pose {self.method.value})", status="start",
                           pose=[round(best.x, 2), round(best.y, 2), round(best.yaw, 3)],
                           score=round(best.score, 4), plane_voxels=len(planes))
            self.here, self.looks_here = None, 0
            outcome = ctx.executor.drive_to((best.x, best.y))
            if outcome.status is not StepStatus.DONE:
                failures += 1
                ctx.trace.emit("action", action=f"(view-pose {self.method.value})",
                               status="failed", detail=outcome.detail)
                if failures >= MAX_DRIVE_FAILURES:
                    return self._end(Outcome.GAVE_UP, f"{failures} view poses unreachable")
                continue
            ctx.robot.turn_to(best.yaw)
            self.poses += 1
            found = known_target(ctx)  # seen while driving there (option watch)
            if found is None:
                found = self.perceive(planes, density, 1 if self.relooks() else None)
            ctx.trace.emit("action", action=f"(view-pose {self.method.value})", status="done",
                           poses=self.poses, search_time_s=round(self.search_time(), 2))
            if found is not None:
                return self._found(found)
            if self.relooks():
                x, y, yaw = ctx.robot.pose
                self.here = ScoredPose(x, y, yaw, 0.0)

    def _found(self, found: KnownObject) -> SearchResult:
        self.learn(found)
        self.result.found = found
        where = ", ".join(f"{v:.2f}" for v in found.position)
        return self._end(Outcome.FOUND, f"{found.label} at ({where}) in {found.room}")

    def relooks(self) -> bool:
        """Option `relook` with `utility: rate` (not `random`): after each look that found
        nothing, staying for another look here competes with the sampled poses."""
        return (self.opt["relook"] and self.opt["utility"] == "rate"
                and self.method is not ViewMethod.RANDOM)

    def look_s(self) -> float:
        """Seconds of looking a pose is rated for: `frustums` x (depth frame + detection)."""
        body = self.ctx.body
        return self.opt["frustums"] * (body.scan_time + body.sensing_time)

    def stay_pose(self, planes: SupportingPlanes, density: np.ndarray) -> ScoredPose | None:
        """Where the robot stands, scored by eq. 2 on the updated belief like the samples, if
        it looked from here last and may look again (`max_looks` per pose, a safety bound)."""
        if self.here is None or self.looks_here >= self.opt["max_looks"]:
            return None
        ctx = self.ctx
        score = score_poses(np.array([ctx.robot.pose]), planes.points, density, ctx.body,
                            ViewOptions(pan_sweep=math.radians(self.opt["pan_sweep_deg"]),
                                        occlusion=ctx.mind.voxels))[0]  # fmt: skip
        self.here = ScoredPose(self.here.x, self.here.y, self.here.yaw, float(score))
        return self.here

    def choose(self, poses: tuple[ScoredPose, ...], stay: ScoredPose | None = None
               ) -> ScoredPose:  # fmt: skip
        """Option `utility: rate`: the pose with the most density per second of getting there
        and looking (`avs_planner.qsr.best_rate`); `stay`, the robot's own pose, needs no
        driving (its rate is its score per `look_s`) and wins when it is at least as good."""
        ctx = self.ctx
        look = self.look_s()
        rates = pose_rates(poses, ctx.mind.grid, ctx.robot.pose, ctx.body, look)
        k = int(np.argmax(rates)) if len(rates) and np.isfinite(rates).any() else 0
        if stay is not None and stay.score > 0.0 and (
                not len(rates) or stay.score / look >= rates[k]):
            ctx.trace.emit("belief", stay_rate=round(stay.score / look, 5),
                           move_rate=round(float(rates[k]), 5) if len(rates) else None)
            return stay
        return poses[k]

    def look_again(self, planes: SupportingPlanes, density: np.ndarray) -> bool:
        """One more look from where the robot stands: the best of the nine frustums on the
        belief after its misses here (the frustum just used included). True when it found
        the target (in `self.result.found`); with no density left in view here, the robot
        will not consider staying again."""
        before = self.looks_here
        found = self.perceive(planes, density, 1, again=True)
        if found is not None:
            self.result.found = found
            return True
        if self.looks_here == before:  # rated as staying, but no frustum here sees density
            self.here = None
        return False

    def search_time(self) -> float:
        return self.ctx.robot.clock - self.search_start

    def _end(self, outcome: Outcome, reason: str) -> SearchResult:
        self.result.details = {
            "method": self.method.value, "poses": self.poses,
            "search_time_s": round(self.search_time(), 2),
            "survey_time_s": round(self.survey_s, 2),
            "landmarks": [{"label": lm.label, "x": round(lm.x, 2), "y": round(lm.y, 2),
                           "facing_deg": round(math.degrees(lm.facing), 1)}
                          for lm in self.landmarks],
            "knowledge": self.knowledge_from,
        }  # fmt: skip
        return self.ctx.end(self.result, outcome, reason)

    # -- perception --

    def survey(self) -> None:
        """Look round here and at a few frontier stops: maps, voxels, landmarks (not the
        target)."""
        ctx = self.ctx
        labels = tuple(sorted(self.knowledge.fronts))
        agree = ctx.executor.config.agree
        tracker = LandmarkTracker(labels, agree[0], agree[1])
        ctx.trace.emit("action", action="(survey)", status="start", labels=list(labels))
        ctx.executor.look_around()
        self._look_round(tracker)
        for _ in range(self.opt["survey_stops"]):
            if ctx.budget_spent():
                break
            target = ctx.executor.nearest_placeholder()
            if target is None:
                break
            explore(ctx, target)
            self._look_round(tracker)
        self.landmarks = landmarks_from(tracker, ctx.mind.grid, ctx.mind.config.robot_radius)
        ctx.trace.emit("action", action="(survey)", status="done",
                       landmarks={lb: sum(lm.label == lb for lm in self.landmarks)
                                  for lb in labels})

    def _look_round(self, tracker: LandmarkTracker) -> None:
        """Depth frames and two landmark detections in each of `survey_headings` directions."""
        ctx = self.ctx
        robot, mind = ctx.robot, ctx.mind
        tilt = -math.atan2(ctx.body.camera_height - SUPPORT_HEIGHT, LOOK_DISTANCE)
        headings = self.opt["survey_headings"]
        yaw = robot.pose[2]
        for k in range(headings):
            robot.turn_to(yaw + 2 * math.pi * k / headings)
            robot.look(0.0, tilt)
            mind.integrate(robot.scan())
            self._depth()
            for _ in range(2):
                for seen in robot.detect(list(tracker.labels)):
                    if seen.label in tracker.labels:
                        tracker.add(seen.label, seen.position, robot.pose[:2])
        ctx.executor.sense([robot.pose])

    def _depth(self) -> None:
        size = (self.opt["depth_columns"], self.opt["depth_rows"])
        self.ctx.mind.integrate_depth(self.ctx.robot.depth(size))

    def frustums_here(self, points: np.ndarray, density: np.ndarray,
                      visible: np.ndarray | None = None):  # noqa: ANN201
        """The nine frustums ranked again where the robot really stands (the executor stops
        within its arrival distance of the pose), with line of sight from there."""
        body, mind = self.ctx.body, self.ctx.mind
        pose = np.asarray(self.ctx.robot.pose, dtype=float)
        if visible is None:
            camera = np.array([[pose[0], pose[1], body.camera_height]])
            visible = line_of_sight(mind.voxels, camera, points)[0]
        return rank_frustums(pose, points, density, body, body.detect_range, 0.0, visible)

    def perceive(self, planes: SupportingPlanes, density: np.ndarray, looks: int | None = None,
                 again: bool = False) -> KnownObject | None:
        """Look with the best frustums (a depth frame each, for the 3D map), `looks` of
        them (default `frustums`), detect the target and confirm it with a second frame. With
        `rerank`, after a look that found nothing the frustums not yet used here are ranked
        again on the updated belief (the look's voxels times `seen_weight`), as the next pose
        is. `again`: a look after staying (any frustum, the ones used here included)."""
        ctx = self.ctx
        body = ctx.body
        points = planes.points
        pose = np.asarray(ctx.robot.pose, dtype=float)
        camera = np.array([[pose[0], pose[1], body.camera_height]])
        visible = line_of_sight(ctx.mind.voxels, camera, points)[0]
        frustums = list(self.frustums_here(points, density, visible))
        if again:
            frustums = [f for f in frustums if f.score > 0.0]
        used: list[tuple[float, float]] = []
        for i in range(self.opt["frustums"] if looks is None else looks):
            if self.opt["rerank"] and i > 0:
                fresh = self.frustums_here(points, self.density(planes), visible)
                frustums = [f for f in fresh if (f.pan, f.tilt) not in used]
            elif i > 0:
                frustums = frustums[1:]
            if not frustums or (i > 0 and frustums[0].score <= 0.0):
                break
            f = frustums[0]
            if self.search_time() >= self.opt["abort_s"]:
                break
            used.append((f.pan, f.tilt))
            self.looks_here += 1
            ctx.robot.look(f.pan, f.tilt)
            ctx.trace.emit("action", action="(look)", pan=round(f.pan, 3), tilt=round(f.tilt, 3),
                           score=round(f.score, 4), again=again)
            x, y, yaw = ctx.robot.pose
            self.looks.append(_Look(np.array([x, y, body.camera_height]), yaw + f.pan, f.tilt))
            self._depth()
            found = self.look()
            if found is not None:
                return found
        return None

    def look(self) -> KnownObject | None:
        """One view: a detection of the target, confirmed when one of up to `confirm_frames`
        further frames sees it again within the executor's agreement distance (a miss of the
        second frame alone does not throw a real detection away)."""
        ctx = self.ctx
        ex, label = ctx.executor, ctx.target
        ex.stats.views += 1
        first = [s for s in ctx.robot.detect([label]) if s.label == label]
        for s in first:
            ex.stats.detections.append((s.position[0], s.position[1], label, True))
        if not first:
            ctx.trace.emit("observation", label=label, detected=False)
            return None
        agree = ex.config.agree[0]
        again: list = []
        for _ in range(self.opt["confirm_frames"]):
            again = [s for s in ctx.robot.detect([label]) if s.label == label
                     and math.dist(s.position, first[0].position) <= agree]
            if again:
                break
        ctx.trace.emit("observation", label=label, detected=bool(again),
                       position=[round(v, 2) for v in first[0].position])
        return _confirm(ctx, first[0]) if again else None

    # -- belief --

    def _prepare_mixture(self) -> None:
        if self.method is not ViewMethod.QSR:
            return
        result = build_mixture(self.knowledge, self.ctx.target, self.landmarks,
                               rng=self.ctx.executor.seed)
        self.ctx.trace.emit("belief", qsr_mixture=result.status.value,
                            components=len(result.mixture) if result.built else 0,
                            knowledge=self.knowledge_from)
        self.mixture = result.mixture if result.built else None

    def density(self, planes: SupportingPlanes) -> np.ndarray:
        """The method's density over the plane voxels, times `seen_weight` per covering look."""
        uniform = planes.uniform_density()
        base = uniform
        if self.method is ViewMethod.QSR and self.mixture is not None:
            qsr = planes.density(self.mixture)
            if qsr.sum() > 0.0:
                floor = self.opt["uniform_floor"]
                base = (1.0 - floor) * qsr + floor * uniform
        weights = base * self.seen_factor(planes.points)
        total = weights.sum()
        return weights / total if total > 0.0 else uniform

    def seen_factor(self, points: np.ndarray) -> np.ndarray:
        body = self.ctx.body
        factor = np.ones(len(points))
        for look in self.looks:
            inside = in_frustums(look.camera, np.array([look.heading]), np.array([look.tilt]),
                                 points, (body.hfov, body.vfov), body.detect_range)[0]
            factor[inside] *= self.opt["seen_weight"]
        return factor

    # -- learning --

    def learn(self, found: KnownObject) -> None:
        if not self.opt["learn"] or not self.landmarks:
            return
        update = learn_from_observation(self.knowledge, found.label, found.position,
                                        self.landmarks)
        self.ctx.trace.emit("belief", qsr_learnt=[d.text() for d in update.credited])
        if not update.credited:
            return
        self.knowledge = update.knowledge
        if self.ctx.experience is not None:
            self.ctx.experience.learn_qsr(update.credited)
