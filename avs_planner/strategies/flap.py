"""FLAP as a strategy: continual expected-time view planning in the 3D map, after Gedicke,
Günther and Hertzberg, "FLAP for CAOS: Forward-Looking Active Perception for Clutter-Aware
Object Search".

The search region is the space above the supports the robot knows for the target (tables,
shelves, ... from `mind.objects`; their labels come from the knowledge base through the state
builder), one box per support (overlapping boxes of one label merge, like the FLAP paper's shelf
arrangements), each with P_i = `p_volume` (the FLAP paper: 0.2) or, with `p_volume` <= 0, the
conceptual map's P(target on it). Each cycle `FlapSearch` samples views on the current maps,
plans (branch and bound, or greedy with `greedy: true`) and returns the first view; the robot
drives there on the 2D grid, lifts its torso, points its head at the view's target, takes a
depth frame into `mind.voxels` and looks for the target (a detection counts once a second
frame repeats it). The search gives up when p(V̂(S)) < omega (the views can no longer find
the target), and stops at the budget.

Supports must be known first: with `pre_explore` the episode's preparation (`prepare`, before
the clock starts) surveys the building, detecting supports at every stop and, with
`prior_map: true`, integrating depth frames so the 3D map exists before the search (the
FLAP paper's "previously recorded map"); otherwise the search itself surveys until it knows
supports (and may find the target on the way). `reset_region: true` forgets the 3D map inside
the search region at the start (the FLAP paper's outdated map).
"""

from __future__ import annotations

import math
import time
import weakref
from dataclasses import dataclass, field

import numpy as np

from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import Outcome, SearchResult, StepOutcome, StepStatus
from avs_planner.flap import (
    FlapOptions,
    FlapSearch,
    PlannerOptions,
    SearchStatus,
    TargetBelief,
    TargetVolume,
    View,
    ViewPose,
)
from avs_planner.flap.errors import FlapError
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.looking import _look, known_target
from conceptual_map.errors import MapError
from conceptual_map.metric import plan_path

SURVEY_TILTS = (0.0, -0.6)  # rad: depth frames per survey heading (ahead, down at tables)
SEARCH_SURVEY_TILTS = (-0.3,)  # while the clock runs: one frame per heading, where the
# detector looks (half the depth work of two tilts; FLAP's own views map the region densely)
SURVEY_DEPTH_COLUMNS = 48  # before the clock (the prior map)
SEARCH_SURVEY_DEPTH_COLUMNS = 32  # while the clock runs: cheaper; FLAP's views map densely
MAX_SURVEY_STOPS = 60


@dataclass
class _Head:
    """What the strategy last commanded (the adapter reports only the base pose)."""

    torso: float
    pan: float = 0.0
    tilt: float = 0.0
    drive: str = ""  # how the last drive to a view ended
    fit: list = field(default_factory=list)  # driving-time samples, kept from region to region


# ---- preparation and survey ------------------------------------------------------------------

def prepare(ctx: SearchContext) -> None:
    """Before the clock starts (episode `pre_explore`): survey the building, detecting the
    target's supports, with depth frames into the 3D map when `prior_map` is set."""
    survey(ctx, depth=bool(ctx.options["prior_map"]), find=False)  # ends with no placeholder
    # left untried twice, so the search gives up once the region is searched (no re-survey)
    ctx.trace.emit("flap", event="prepared", supports=_support_names(ctx),
                   voxels=_known_voxels(ctx))


def survey(ctx: SearchContext, depth: bool, find: bool, until_support: bool = False,
           columns: int = SURVEY_DEPTH_COLUMNS,
           tilts: tuple[float, ...] = SURVEY_TILTS) -> KnownObject | None:
    """Visit placeholders nearest-first (frontier exploration), looking all round at every
    stop for supports (and the target when `find`); returns the target once confirmed. With
    `until_support` it stops after the first stop that registered a new support."""
    mind, ex = ctx.mind, ctx.executor
    known = len(_support_names(ctx))
    ex.look_around()
    found = _survey_stop(ctx, depth, find, columns, tilts)
    for _ in range(MAX_SURVEY_STOPS):
        if found is not None or (find and ctx.budget_spent()):
            break
        if until_support and len(_support_names(ctx)) > known:
            break
        target = ex.nearest_placeholder()
        if target is None:
            break
        mind.tried_placeholders[target] = mind.tried_placeholders.get(target, 0) + 1
        goal = mind.place_map.placeholders[target].position
        outcome = ex.drive_to(goal, stop=lambda t=target: t not in mind.place_map.placeholders)
        if find and found is None:
            found = known_target(ctx)  # the executor's watch confirmed it on the way
            if found is not None:
                break
        if outcome.status is StepStatus.DONE:
            ex.look_around()
            found = _survey_stop(ctx, depth, find, columns, tilts)
    return found


def _survey_stop(ctx: SearchContext, depth: bool, find: bool, columns: int,
                 tilts: tuple[float, ...]) -> KnownObject | None:
    robot, headings = ctx.robot, ctx.options["survey_headings"]
    if find and (known := known_target(ctx)) is not None:
        return known  # confirmed by the executor's watch (its look around, or on the way)
    supports = _support_labels(ctx)
    labels = [*supports, ctx.target] if find else supports
    yaw = robot.pose[2]
    for k in range(headings):
        robot.turn_to(yaw + 2 * math.pi * k / headings)
        if depth:
            for tilt in tilts:
                robot.look(0.0, tilt)
                ctx.mind.integrate_depth(robot.depth(_size(columns)))
        robot.look(0.0, SURVEY_TILTS[-1] / 2)
        if not labels:
            continue
        seen = robot.detect(labels)
        if find and any(s.label == ctx.target for s in seen):
            found = _look(ctx)
            if found is not None:
                return found
        _register_supports(ctx, [s for s in seen if s.label in supports])
    return None


def _register_supports(ctx: SearchContext, seen: list) -> None:
    """Supports seen in a frame become known objects when another detection repeats them (a
    second frame now, or any later frame of the survey: a pose may see a support only at the
    edge of the image) and no known object of their label is within `same_object` m."""
    if not seen:
        return
    ex, mind = ctx.executor, ctx.mind
    pending = _PENDING.setdefault(ex, [])
    again = ctx.robot.detect(sorted({s.label for s in seen}))
    near = ex.config.agree[1]
    for s in seen:
        repeated = [a for a in (*again, *pending) if a.label == s.label
                    and math.dist(a.position, s.position) <= near]
        if not repeated:
            pending.append(s)
            continue
        if any(o.label == s.label and math.dist(o.position[:2], s.position[:2])
               <= ex.config.same_object for o in mind.objects.values()):
            continue
        try:
            obj = mind.add_object(s.label, s.position)
        except ValueError:
            continue  # no room known there yet
        ctx.trace.emit("observation", label=s.label, detected=True, registered=obj.id,
                       position=[round(v, 2) for v in s.position])


# per episode (its executor): support detections that no other one has repeated yet
_PENDING: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _support_labels(ctx: SearchContext) -> list[str]:
    return list(ctx.builder.supports)


def _support_names(ctx: SearchContext) -> list[str]:
    labels = set(_support_labels(ctx))
    return [f"{o.id}:{o.label}" for o in ctx.mind.objects.values() if o.label in labels]


def _known_voxels(ctx: SearchContext) -> int:
    voxels = ctx.mind.voxels
    return 0 if voxels is None else int((voxels.states().reshape(-1) != 0).sum())


def _size(columns: int) -> tuple[int, int]:
    return int(columns), max(1, int(columns) * 3 // 4)


# ---- the search region -----------------------------------------------------------------------

def support_box(obj: KnownObject, reach: float, height: float, below: float
                ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """The box where a target on a detected support would be: `reach` m either side of its
    detected centre, from `below` (< 0: the top is a noisy estimate) under its top (twice the
    detected centre's height: a detection's centre is half the support's) to `height` above."""
    x, y, z = obj.position
    top = max(0.3, 2.0 * z)
    return (x - reach, y - reach, top + below), (x + reach, y + reach, top + height)


def support_volumes(ctx: SearchContext, skip: set[str] = frozenset()) -> list[TargetVolume]:
    """One box above each known support of the target (but those in `skip`); overlapping
    boxes of a label merge. A volume's name lists its supports' ids joined by '+'."""
    o, mind = ctx.options, ctx.mind
    labels = set(_support_labels(ctx))
    boxes: list[list] = []  # [lo, hi, label, P, ids]
    reach, height = o["support_reach"], o["volume_height"]
    for obj in mind.objects.values():
        if obj.label not in labels or obj.id in skip:
            continue
        p = o["p_volume"] if o["p_volume"] > 0 else _p_on(ctx, obj)
        lo, hi = support_box(obj, reach, height, ctx.executor.config.above_support[0])
        boxes.append([list(lo), list(hi), obj.label, p, [obj.id]])
    merged = True
    while merged:
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, b = boxes[i], boxes[j]
                if a[2] == b[2] and all(a[0][k] < b[1][k] and b[0][k] < a[1][k]
                                        for k in range(3)):
                    p = (a[3] if o["p_volume"] > 0 else 1 - (1 - a[3]) * (1 - b[3]))
                    boxes[i] = [[min(a[0][k], b[0][k]) for k in range(3)],
                                [max(a[1][k], b[1][k]) for k in range(3)], a[2], p, a[4] + b[4]]
                    del boxes[j]
                    merged = True
                    break
            if merged:
                break
    return [TargetVolume(tuple(lo), tuple(hi), min(0.95, max(0.01, p)), "+".join(ids))
            for lo, hi, _, p, ids in boxes]


def task_volumes(ctx: SearchContext) -> list[TargetVolume]:
    """The region the task gives (option `volumes`, as the FLAP paper's search tasks do)."""
    return parse_volumes(ctx.options["volumes"], ctx.options["p_volume"])


def parse_volumes(given: object, p_default: float) -> list[TargetVolume]:
    """Option `volumes`: one box per entry {lo, hi, p (default `p_volume`), name}. Raises
    FlapError naming the bad entry."""
    if not isinstance(given, list):
        raise FlapError(f"option 'volumes' must be a list of boxes, got {given!r}")
    out = []
    for k, entry in enumerate(given):
        where = f"option 'volumes' entry {k}"
        if not isinstance(entry, dict) or not {"lo", "hi"} <= set(entry):
            raise FlapError(f"{where}: need a mapping with lo and hi, got {entry!r}")
        unknown = sorted(set(entry) - {"lo", "hi", "p", "name"})
        if unknown:
            raise FlapError(f"{where}: unknown key(s) {', '.join(unknown)}")
        try:
            lo = tuple(float(v) for v in entry["lo"])
            hi = tuple(float(v) for v in entry["hi"])
            p = float(entry.get("p", p_default))
        except (TypeError, ValueError) as exc:
            raise FlapError(f"{where}: lo, hi and p must be numbers ({exc})") from None
        volume = TargetVolume(lo, hi, p, str(entry.get("name", f"volume{k}")))
        try:
            volume.check()
        except FlapError as exc:
            raise FlapError(f"{where}: {exc}") from None
        out.append(volume)
    return out


def check_options(options: dict) -> None:
    """The registry's check of flap's options beyond their types."""
    parse_volumes(options["volumes"], options["p_volume"])


def _p_on(ctx: SearchContext, obj: KnownObject) -> float:
    try:
        return float(ctx.mind.cmap.p_object_at(ctx.target, ("on", obj.id)))
    except Exception:  # noqa: BLE001 - a label the knowledge lacks: the FLAP paper's prior
        return 0.2


# ---- the search ------------------------------------------------------------------------------

def run(ctx: SearchContext) -> SearchResult:
    """Search the known supports' region with FLAP; when it is exhausted (omega), survey on to
    the next support (or, with none known yet, survey until one is seen)."""
    result = SearchResult(Outcome.GAVE_UP, "")
    mind, ex = ctx.mind, ctx.executor
    head = _Head(torso=max(0.0, ctx.robot.camera_height - ctx.body.camera_height))
    searched: set[str] = set()
    reset, why = bool(ctx.options["reset_region"]), "no support of the target is known"
    given = task_volumes(ctx)
    if given:  # the task's region: searched once, to the omega test
        ended = _search_region(ctx, result, given, head, reset)
        return ended or ctx.end(result, Outcome.GAVE_UP,
                                "the given region is searched (p(V̂(S)) < omega)")
    while True:
        stop = ctx.budget_spent()
        if stop:
            return ctx.end(result, Outcome.TIMEOUT, stop)
        volumes = support_volumes(ctx, skip=searched)
        if volumes:
            ended = _search_region(ctx, result, volumes, head, reset)
            if ended is not None:
                return ended
            searched |= {oid for v in volumes for oid in v.name.split("+")}
            why = "the known supports are searched (p(V̂(S)) < omega)"
            if not ctx.options["survey_on"]:
                return ctx.end(result, Outcome.GAVE_UP, why)
        elif mind.place_map.places and ex.nearest_placeholder() is None:
            return ctx.end(result, Outcome.GAVE_UP, f"{why}; nothing left to explore")
        else:
            found = survey(ctx, depth=True, find=True, until_support=True,
                           columns=SEARCH_SURVEY_DEPTH_COLUMNS, tilts=SEARCH_SURVEY_TILTS)
            if found is not None:
                return _found(ctx, result, found)
        reset = False  # only the map known before the search is taken as out of date


def _search_region(ctx: SearchContext, result: SearchResult, volumes: list[TargetVolume],
                   head: _Head, reset: bool) -> SearchResult | None:
    """The FLAP cycle over one region until the target is found (the ended result), the
    budget is spent (ditto), or p(V̂(S)) < omega (None)."""
    o, mind, robot = ctx.options, ctx.mind, ctx.robot
    mind.integrate_depth(_detectable(robot.depth(_size(o["depth_columns"])), ctx.body))  # (makes
    # the map if there is none)
    if reset:
        for volume in volumes:
            mind.voxels.reset_box(volume.lo, volume.hi)
    tracker = TargetBelief(mind.voxels, volumes)
    log0 = float(tracker.log_miss().sum())
    ctx.trace.emit("flap", event="region", volumes=[
        {"name": v.name, "lo": [round(c, 2) for c in v.lo], "hi": [round(c, 2) for c in v.hi],
         "p": round(v.probability, 3)} for v in volumes],
        p_total=round(-math.expm1(log0), 4), cells=tracker.size)
    planner = PlannerOptions(omega=o["omega"], time_limit=o["time_limit_s"] or None)
    search = FlapSearch(ctx.body, volumes, FlapOptions(views=o["views"], clusters=o["clusters"],
                                                       planner=planner, greedy=o["greedy"]))
    search.fit_samples = head.fit  # the same robot on the same floor: fewer A* to price
    for k in range(o["max_views"]):
        stop = ctx.budget_spent()
        if stop:
            return ctx.end(result, Outcome.TIMEOUT, stop)
        began = time.perf_counter()
        decision = search.decide(mind.voxels, mind.grid, ViewPose(*robot.pose, head.torso,
                                                                  head.pan, head.tilt))
        plan = decision.plan
        ctx.trace.emit("flap", event="decision", cycle=k, status=decision.status.value,
                       # unrounded: the value the omega test compared (rounding 0.349956 to
                       # 4 places would print a 'done' decision at 0.35, above omega 0.35)
                       candidates=decision.candidates, p_remaining=decision.p_remaining,
                       planned=len(plan.sequence) if plan else 0,
                       expected_time=(round(plan.expected_time, 2) if plan and
                                      math.isfinite(plan.expected_time) else None),
                       stop=plan.stop.value if plan else None,
                       exact=bool(plan and plan.exact),
                       seconds={**{n: round(s, 3) for n, s in decision.seconds.items()},
                                "total": round(time.perf_counter() - began, 3)})
        if decision.status is not SearchStatus.GO:
            return None  # DONE: p(V̂(S)) < omega; NO_VIEWS: nothing reachable sees the region
        found = _visit(ctx, decision.view, head)
        view = decision.view
        off = math.dist(robot.pose[:2], (view.pose.x, view.pose.y))
        dropped = 0
        if off > ctx.executor.config.arrive:
            search.unreachable(view)  # what it saw from where it stopped is in the map anyway
        else:
            dropped = search.sensed(mind.voxels, view)
        before = float(tracker.log_miss().sum())
        tracker.refresh(mind.voxels)
        after = float(tracker.log_miss().sum())
        ctx.trace.emit("flap", event="view", cycle=k, pose=[round(v, 3) for v in (
            *robot.pose, head.torso, head.pan, head.tilt)],
            p_seen=round(-math.expm1(before - after), 5),
            survival=round(math.exp(log0 - after), 5), expected_cells=int(decision.view.cells.size),
            unrevealed=dropped, known_voxels=_known_voxels(ctx), drive=head.drive,
            off=round(off, 3),
            found=found is not None)
        if found is not None:
            return _found(ctx, result, found)
    return ctx.end(result, Outcome.TIMEOUT, f"{o['max_views']} views in one region")


def _visit(ctx: SearchContext, view: View, head: _Head) -> KnownObject | None:
    """Drive to the view, stand on its pose, point the head at its target, take a depth frame
    into the 3D map and look for the target."""
    robot, body, pose = ctx.robot, ctx.body, view.pose
    outcome = (ctx.executor.drive_to((pose.x, pose.y)) if ctx.options["sense_en_route"]
               else _drive_quietly(ctx, (pose.x, pose.y)))
    head.drive = outcome.status.value if not outcome.detail else f"{outcome.status.value}: " \
        f"{outcome.detail}"
    if outcome.status is StepStatus.DONE and math.dist(robot.pose[:2], (pose.x, pose.y)) > 0.02:
        robot.move_along([(pose.x, pose.y)])  # the last few cm (refused if it would collide)
    x, y, _ = robot.pose
    tx, ty, tz = view.target
    head.torso = body.torso.clip(pose.torso)
    head.pan = body.pan.clip(pose.pan)
    head.tilt = body.tilt.clip(math.atan2(tz - (body.camera_height + head.torso),
                                          max(1e-6, math.hypot(tx - x, ty - y))))
    robot.turn_to(math.atan2(ty - y, tx - x) - head.pan)
    robot.set_torso(head.torso)
    robot.look(head.pan, head.tilt)
    ctx.mind.integrate_depth(_detectable(robot.depth(_size(ctx.options["depth_columns"])), body))
    return known_target(ctx) or _look(ctx)  # (the watch may have confirmed it on the way)


@dataclass(frozen=True)
class _Frame:
    """A depth frame (conceptual_map's DepthFrameLike) with a shorter max range."""

    origin: np.ndarray
    directions: np.ndarray
    ranges: np.ndarray
    max_range: float
    time: float


def _detectable(frame, body) -> _Frame:  # noqa: ANN001 - a DepthFrameLike and a RobotBody
    """A search view's depth frame cut at the detector's range: a cell the depth camera sees
    beyond it was not searched (the detector could not have recognised the target there), and
    the sampler predicts a view's cells within that range. Beyond it the rays say nothing."""
    return _Frame(frame.origin, frame.directions, frame.ranges,
                  min(float(frame.max_range), body.detect_range), frame.time)


def _drive_quietly(ctx: SearchContext, goal: tuple[float, float]) -> StepOutcome:
    """The FLAP paper's transition: follow one A* path on the robot's grid to the view, with one
    laser scan at the end, and no sensing on the way (the executor's drive scans every metre,
    classifies each new place and watches for the target: about a third of the search time
    in `flap_two_rooms`, which the transition model does not predict). Falls back to the
    executor's drive when there is no path or the base refuses it."""
    robot, mind = ctx.robot, ctx.mind
    try:
        path = plan_path(mind.grid, robot.pose[:2], goal, mind.config.robot_radius)
    except MapError:
        path = None
    if path is None or not path.found or not robot.move_along(list(path.waypoints[1:])):
        return ctx.executor.drive_to(goal)
    ctx.executor.stats.distance += path.length
    mind.sense(robot.scan(), [robot.pose], robot.clock)
    return StepOutcome(StepStatus.DONE)


def _found(ctx: SearchContext, result: SearchResult, obj: KnownObject) -> SearchResult:
    result.found = obj
    where = ", ".join(f"{v:.2f}" for v in obj.position)
    return ctx.end(result, Outcome.FOUND, f"{obj.label} at ({where}) in {obj.room}")
