"""FLAP views inside the switching planner (option `views: flap` of `strategy: switching`).

The switching planner's CREATEVIEWCONES on a support (`ObjectAt(label, on, support)`) makes
its view cones from FLAP instead of the 2D circle around the support (`support_cones`); the
DT stays the decision layer: it orders the cones, moves, looks and stops with the detector's
false-negative/false-positive model as before. How the two are combined:

- **Region**: the support's box (as the flap strategy's, `flap.support_box`) with the CP's
  P(ObjectAt on the support) as its P_i.
- **3D map**: `mind.voxels`, kept current by a depth frame (cut at the detector's range) at
  every PROCESSVIEWCONE look (`Executor.on_look`); the first CREATEVIEWCONES takes one from
  where the robot stands if there is no map yet.
- **Views**: `ViewSampler` over the box (frontier targets, range, kinematic and
  frontier-normal constraints, optimistic ray casting), the transition table from the robot's
  pose, and FLAP's expected-time plan (branch and bound, eq. 4-9); the first `max_cones`
  views of the plan become cones, each with the base pose, head pan/tilt and torso lift.
- **Probabilities**: the DT models one target: a cone's probability is P_i times the share of
  the box's unknown cells that the cone adds to the cones before it in FLAP's order (the
  uniform per-cell prior of eq. 1 and the set difference of eq. 5, normalised to one
  target); the set's coverage is the share all cones see. `ConeSet.probability` is the mass
  the cones hold (P_i * coverage), so a rejected search reports the share of the box looked
  at (`ViewConeSearch._conclude`).
- **Fallback**: no unknown cell in the box, no view, no reachable view, or a FLAP or map
  error: the 2D cones (the trace event `flap` / `cones` says which and why).

Searches in a room (`ObjectAt(label, in, room)`) keep the 2D room cones.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from avs_planner.body import RobotBody
from avs_planner.dt import ViewCone
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.viewcones import CameraModel, ConeSet, support_cones
from avs_planner.flap import (
    PlannerOptions,
    SequencingProblem,
    TargetBelief,
    TargetVolume,
    ViewPose,
    ViewSampler,
    build_table,
    plan_views,
)
from avs_planner.flap.errors import FlapError
from avs_planner.strategies.flap import _detectable, _size, support_box
from avs_planner.strategies.switching import VIEWS
from conceptual_map.errors import MapError


class FlapViews:
    """A `support_cones` replacement (same call) that asks FLAP for the views."""

    def __init__(self, robot: Any, body: RobotBody, emit: Any, below: float,
                 views: int = 80, clusters: int = 25, max_cones: int = 6,
                 time_limit: float = 0.25, reach: float = 0.7, height: float = 0.3,
                 depth_columns: int = 48):
        self.robot, self.body, self.emit, self.below = robot, body, emit, below
        self.views, self.clusters, self.max_cones = views, clusters, max_cones
        self.time_limit, self.reach, self.height = time_limit, reach, height
        self.depth_columns = depth_columns
        self.calls = 0
        self.mind: Mind | None = None

    def on_look(self) -> None:
        """Before a PROCESSVIEWCONE detection: the frame's depth into the 3D map."""
        if self.mind is not None:
            self.mind.integrate_depth(_detectable(self.robot.depth(_size(self.depth_columns)),
                                                  self.body))

    def __call__(self, mind: Mind, support: KnownObject, p: float, camera: CameraModel,
                 key: str) -> ConeSet:
        self.mind = mind
        began = time.perf_counter()
        try:
            made, note = self._flap_cones(mind, support, p, key)
        except (FlapError, MapError) as exc:  # e.g. no view reachable: the 2D cones
            made, note = None, str(exc)
        if made is None:
            made = support_cones(mind, support, p, camera, key)
        self.emit("flap", event="cones", support=support.id, flap=note is None,
                  note=note, cones=len(made.cones), coverage=round(made.coverage, 3),
                  seconds=round(time.perf_counter() - began, 3))
        return made

    def _flap_cones(self, mind: Mind, support: KnownObject, p: float, key: str
                    ) -> tuple[ConeSet | None, str | None]:
        if mind.voxels is None:
            self.on_look()  # makes the map (it covers the 2D grid's extent)
        lo, hi = support_box(support, self.reach, self.height, self.below)
        p_i = min(0.95, max(1e-3, float(p)))
        belief = TargetBelief(mind.voxels, [TargetVolume(lo, hi, p_i, support.id)])
        unknown = int(belief.unknown.sum())
        if unknown == 0:
            return None, "no unknown cell left in the support's box"
        self.calls += 1
        views = ViewSampler(mind.voxels, mind.grid, self.body, belief).sample(
            self.views, seed=self.calls)
        if not views:
            return None, "no view sees the support's box"
        x, y, yaw = self.robot.pose
        torso = max(0.0, self.robot.camera_height - self.body.camera_height)
        table = build_table(self.body, mind.grid, ViewPose(x, y, yaw, torso, 0.0, 0.0),
                            [v.pose for v in views], self.clusters, seed=self.calls)
        views = [views[k] for k in table.kept]
        problem = SequencingProblem.build([v.cells for v in views], belief.log_miss(),
                                          table.start, table.times)
        plan = plan_views(problem, PlannerOptions(time_limit=self.time_limit))
        if not plan.sequence:
            return None, "FLAP planned no view"
        seen = np.zeros(belief.size, dtype=bool)
        cones = []
        for k in plan.sequence[: self.max_cones]:
            view = views[k]
            cells = np.asarray(view.cells, dtype=np.int64)
            new = cells[belief.unknown[cells] & ~seen[cells]]
            seen[new] = True
            pose = view.pose
            cones.append(ViewCone(f"{key}-{len(cones)}", (pose.x, pose.y, pose.yaw),
                                  p_i * new.size / unknown,
                                  head=(self.body.pan.clip(pose.pan),
                                        self.body.tilt.clip(pose.tilt)),
                                  torso=self.body.torso.clip(pose.torso)))
        coverage = float(seen.sum()) / unknown
        return ConeSet(tuple(cones), coverage, p_i * coverage), None


def make(views: str, ctx: Any) -> FlapViews | None:
    """The cone maker for the switching strategy's `views` option (None: the 2D cones)."""
    if views not in VIEWS:
        raise FlapError(f"option 'views' must be one of {', '.join(VIEWS)}, got {views!r}")
    if views == "cones":
        return None
    return FlapViews(ctx.robot, ctx.body, ctx.trace.emit,
                     ctx.executor.config.above_support[0])

