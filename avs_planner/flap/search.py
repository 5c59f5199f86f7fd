"""Continual FLAP search (§3.2): each cycle re-samples views on the updated map, keeps and
re-evaluates the views still planned, rebuilds the transition table and plans again; the
caller drives to the first view, senses, integrates depth, and asks again.

The search is over when p(V̂(S)) < omega: the views can no longer find the target.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from avs_planner.body import RobotBody
from avs_planner.flap.planner import (
    PlannerOptions,
    PlanResult,
    StopReason,
    plan_greedy,
    plan_views,
)
from avs_planner.flap.problem import SequencingProblem
from avs_planner.flap.sampling import SamplerOptions, View, ViewPose, ViewSampler
from avs_planner.flap.target import TargetBelief, TargetVolume
from avs_planner.flap.transitions import build_table
from conceptual_map.metric import OccupancyGrid, VoxelMap


class SearchStatus(Enum):
    """What the robot should do after a cycle."""

    GO = "go"  # drive to `Decision.view` and sense
    DONE = "done"  # p(V̂(S)) < omega: the region is searched as far as the views can tell
    NO_VIEWS = "no_views"  # no reachable view sees any unknown cell of the region


@dataclass(frozen=True)
class FlapOptions:
    """Views per cycle, table clusters, planner options; greedy=True is the baseline."""

    views: int = 200
    sample_timeout: float | None = None
    clusters: int = 50
    planner: PlannerOptions = field(default_factory=PlannerOptions)
    sampler: SamplerOptions = field(default_factory=SamplerOptions)
    greedy: bool = False
    fit_pairs: int = 16  # exact A* times for the first cycle's driving regression
    refit_pairs: int = 4  # new ones per later cycle (the last 2 * fit_pairs are kept)


@dataclass(frozen=True)
class Decision:
    """One cycle's outcome: the next view (if any), the plan, and the cycle's timings."""

    status: SearchStatus
    view: View | None
    plan: PlanResult | None
    p_remaining: float  # p(V̂(S)) over this cycle's views
    candidates: int
    seconds: dict[str, float]


class FlapSearch:
    """FLAP's plan-act cycle over one search region; holds the views planned last cycle."""

    def __init__(
        self, body: RobotBody, volumes: Sequence[TargetVolume], options: FlapOptions | None = None
    ):
        self.body, self.volumes = body, list(volumes)
        self.options = options or FlapOptions()
        self.planned: list[View] = []
        self.cycle = 0
        self.exhausted = np.zeros(0, dtype=bool)  # region cells given up on (see `sensed`)
        self.blocked: list[tuple[float, float]] = []  # view positions the robot failed to reach
        self.fit_samples: list[tuple[float, float]] = []  # (grid m, driving s) for the table

    def unreachable(self, view: View, radius: float = 0.3) -> None:
        """The robot could not get to `view`: no view within `radius` m of it is planned again
        (its cells stay in play for views elsewhere)."""
        self.blocked.append((view.pose.x, view.pose.y))
        self.block_radius = radius

    def sensed(self, voxels: VoxelMap, view: View) -> int:
        """After the robot sensed at `view` (or as near it as it got): the cells the view was
        expected to reveal but that the map still has unknown are taken as unobservable from
        the views (optimistic ray casting assumed unknown space free; a solid interior, a gap
        between depth rays, or a pose not quite reached leave them unknown). Without this a
        continual search could choose the same view forever. Returns how many were dropped."""
        belief = TargetBelief(voxels, self.volumes)
        if self.exhausted.size != belief.size:
            self.exhausted = np.zeros(belief.size, dtype=bool)
        cells = np.asarray(view.cells, dtype=np.int64)
        missed = cells[belief.unknown[cells] & ~self.exhausted[cells]]
        self.exhausted[missed] = True
        return int(missed.size)

    def decide(self, voxels: VoxelMap, grid: OccupancyGrid, pose: ViewPose) -> Decision:
        """Plan from the robot's pose on the current maps; returns where to look next."""
        clock = _Clock()
        belief = TargetBelief(voxels, self.volumes)
        if self.exhausted.size == belief.size:
            belief.mark_seen(np.flatnonzero(self.exhausted))
        sampler = ViewSampler(voxels, grid, self.body, belief, self.options.sampler)
        views = sampler.evaluate(self.planned)
        views += sampler.sample(max(0, self.options.views - len(views)),
                                self.options.sample_timeout, seed=self.cycle)  # fmt: skip
        self.cycle += 1
        if self.blocked:
            views = [v for v in views if not _near(v, self.blocked, self.block_radius)]
        clock.lap("sampling")
        p_all = belief.p_views(v.cells for v in views)
        if not views or p_all < self.options.planner.omega:
            self.planned = []
            status = SearchStatus.NO_VIEWS if not views else SearchStatus.DONE
            return Decision(status, None, None, p_all, len(views), clock.laps)
        fresh = self.options.fit_pairs if not self.fit_samples else self.options.refit_pairs
        table = build_table(self.body, grid, pose, [v.pose for v in views], self.options.clusters,
                            fit_pairs=fresh, seed=self.cycle, known=self.fit_samples)
        self.fit_samples[:] = table.samples[-self.options.fit_pairs * 2:]  # (in place: shared)
        views = [views[k] for k in table.kept]
        clock.lap("transitions")
        problem = SequencingProblem.build([v.cells for v in views], belief.log_miss(),
                                          table.start, table.times)  # fmt: skip
        plan = self._plan(problem)
        clock.lap("planning")
        self.planned = [views[k] for k in plan.sequence]
        if not self.planned:
            return Decision(SearchStatus.DONE, None, plan, p_all, len(views), clock.laps)
        return Decision(SearchStatus.GO, self.planned[0], plan, p_all, len(views), clock.laps)

    def _plan(self, problem: SequencingProblem) -> PlanResult:
        if self.options.greedy:
            return plan_greedy(problem, self.options.planner.omega)
        plan = plan_views(problem, self.options.planner)
        if not plan.sequence and plan.stop in (StopReason.TIME_LIMIT, StopReason.NODE_LIMIT):
            return plan_greedy(problem, self.options.planner.omega)  # a limit struck first
        return plan


class _Clock:
    """Seconds per named phase of a cycle."""

    def __init__(self):
        self.laps: dict[str, float] = {}
        self._last = time.perf_counter()

    def lap(self, name: str) -> None:
        now = time.perf_counter()
        self.laps[name] = now - self._last
        self._last = now


def _near(view: View, points: list[tuple[float, float]], radius: float) -> bool:
    return any(math.hypot(view.pose.x - x, view.pose.y - y) < radius for x, y in points)
