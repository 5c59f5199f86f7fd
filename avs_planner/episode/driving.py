"""The driving skill: A* legs on the robot's own grid, re-planned as the grid grows, with a
slimmer margin or through unknown cells when nothing else fits (`Driver.squeeze_path`), and a
blocked leg turned into a keep-out disc the next path goes around (`Driver._blocked`).

`Driver` receives the executor's `SkillContext` (`episode/context.py`: the robot it moves, the
mind whose grid it plans on, the settings, the tallies, the trace) and `sense`, what to do after
every leg (the executor gives the sensing skill's `Sensing.sense`, `episode/sensing.py`: scan,
grow the maps, watch for the target); a drive ends early when `sense` returns the target.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from avs_planner.episode.blockages import Blockage
from avs_planner.episode.context import SkillContext
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import StepOutcome, StepStatus
from conceptual_map.errors import MapError
from conceptual_map.metric import plan_path
from conceptual_map.metric.path_planning import PathResult, PathStatus

TARGET_SEEN = "saw the target on the way"  # a drive stopped early: the watch confirmed it

Point = tuple[float, float]
Pose = tuple[float, float, float]
# after a leg: the poses the leg went through; the target the watch confirmed, if any
Sense = Callable[[list[Pose]], KnownObject | None]


class Driver:
    """Moves the robot to a goal on the growing grid (see the module's doc)."""

    def __init__(self, context: SkillContext, sense: Sense) -> None:
        self.context = context
        self.sense = sense

    def drive_to(self, goal: Point, stop: Callable[[], bool] = lambda: False) -> StepOutcome:
        """Drive leg by leg to `goal`, re-planning the path on the growing grid."""
        ctx = self.context
        robot, mind, cfg = ctx.robot, ctx.mind, ctx.config
        route: list[Point] = []  # the rest of the last A* path
        # the margin that path keeps: a squeeze's is slimmer, and re-checked at the full
        # radius it never holds; re-planned from inside the gap, a full-radius path escapes
        # the start's inflation zone in a straight line and clips the gap's exit corner (a
        # PR2 leaving a 0.74 m gap touched the fridge's corner until it gave up)
        margin = mind.config.robot_radius
        age = detours = 0
        for _ in range(cfg.max_legs):
            if stop():
                return StepOutcome(StepStatus.DONE, "explored on the way")
            here = robot.pose
            if math.dist(here[:2], goal) <= cfg.arrive:
                return StepOutcome(StepStatus.DONE)
            if age >= cfg.replan_legs or not self.clear(route, margin):
                margin = mind.config.robot_radius
                try:
                    path = plan_path(mind.grid, here[:2], goal, margin)
                except MapError as exc:
                    nearby = self._free_near(goal)
                    if nearby is None:
                        return StepOutcome(StepStatus.FAILED, str(exc))
                    goal, route = nearby, []
                    continue
                if not path.found:
                    path, margin = self.squeeze_path(here[:2], goal)
                if not path.found:
                    return StepOutcome(StepStatus.FAILED, self._no_path(goal))
                route, age = list(path.waypoints), 0
            route[0] = here[:2]
            leg, route = _split_leg(route, cfg.leg)
            age += 1
            if not robot.move_along(leg):
                detours += 1
                blockage, why = self._blocked()
                if blockage is None or detours > cfg.detours:
                    return StepOutcome(StepStatus.FAILED, f"blocked {detours} times on the way "
                                       f"to ({goal[0]:.2f}, {goal[1]:.2f}): {why}")
                self.back_off(blockage)
                route = []  # plan around the keep-out disc
                continue
            ctx.stats.distance += sum(math.dist(a, b) for a, b in
                                      zip([here[:2], *leg], leg, strict=False))
            if self.sense([(x, y, robot.pose[2]) for x, y in leg]) is not None:
                # the detector confirmed the target on the way: driving on to a goal picked
                # to look for it is wasted time (the object reaches the planner with this
                # step's outcome, and its next plan reports it)
                return StepOutcome(StepStatus.DONE, TARGET_SEEN)
        return StepOutcome(StepStatus.FAILED, "too many legs")

    def _blocked(self) -> tuple[Blockage | None, str]:
        """The base refused a leg: its contact point becomes a blockage the paths avoid
        (reported to the trace). Returns it (None without a contact point) and what was
        learned."""
        ctx = self.context
        contact = getattr(ctx.robot, "last_contact", None)
        if contact is None:
            return None, "the base refused the leg and gave no contact point"
        blockage = ctx.mind.block(contact, ctx.robot.clock)
        ctx.emit("belief", blocked=blockage.id, at=[round(v, 2) for v in blockage.centre],
                 door=blockage.door, retry_at=round(blockage.until, 1),
                 detail=blockage.describe())
        return blockage, blockage.describe()

    def back_off(self, blockage: Blockage) -> None:
        """Step straight away from the touched point until the robot's centre is outside the
        new keep-out disc. Standing inside it (the refused leg started next to what it
        touched: a corner the scans had not shown), every path out begins in the disc, the
        next one is planned from there past the same corner, and the base touches it again
        until the move fails with a free way round in plain sight (a PR2 leaving a room by
        a sink beside its door touched the sink's corner three times from one pose). A
        back-off the base refuses too is left: the next path is planned from where it is."""
        ctx = self.context
        x, y = ctx.robot.pose[:2]
        cx, cy = blockage.centre
        away = math.dist((x, y), (cx, cy))
        gap = blockage.radius + ctx.mind.grid.resolution - away
        if gap <= 0.0 or away < 1e-6:
            return
        step = (x + (x - cx) / away * gap, y + (y - cy) / away * gap)
        if ctx.robot.move_along([step]):
            ctx.stats.distance += gap
            ctx.emit("belief", backed_off=blockage.id, to=[round(v, 2) for v in step])

    def _no_path(self, goal: Point) -> str:
        """Why no path leads to `goal`, naming the blockages the robot has run into."""
        known = [b.describe() for b in self.context.mind.blockages.items.values()]
        return f"no path to ({goal[0]:.2f}, {goal[1]:.2f})" + (
            f" ({'; '.join(known)})" if known else "")

    def clear(self, route: list[Point], radius: float | None = None) -> bool:
        """The rest of the last path still keeps its margin `radius` (default: the planning
        radius) on the grown grid (so the A* search is not repeated after every leg). The
        robot's own footprint is skipped: the laser never sees the cells under the base."""
        if len(route) < 2:
            return False
        mind = self.context.mind
        grid = mind.grid
        radius = mind.config.robot_radius if radius is None else radius
        free = grid.traversable(radius)
        step = grid.resolution / 2
        start = np.asarray(route[0])
        for a, b in zip(route, route[1:], strict=False):
            n = max(2, int(math.dist(a, b) / step) + 1)
            t = np.linspace(0.0, 1.0, n)[:, None]
            points = np.asarray(a) + t * (np.asarray(b) - np.asarray(a))
            points = points[np.linalg.norm(points - start, axis=1) > radius]
            cells = np.asarray(grid.to_cell(points), dtype=int)
            if (cells < 0).any() or (cells >= np.asarray(free.shape)).any():
                return False
            if not free[cells[:, 0], cells[:, 1]].all():
                return False
        return True

    def squeeze(self, start: Point, goal: Point) -> PathResult:
        """`squeeze_path`'s path alone (the DT's travel costs price cones with it)."""
        return self.squeeze_path(start, goal)[0]

    def squeeze_path(self, start: Point, goal: Point) -> tuple[PathResult, float]:
        """A path with a slimmer margin (the robot may start close to furniture; never below
        its footprint less a cell: `clearance` underestimates by half a cell), then one
        through unknown cells (a laser mounted ahead of the base never sees the cells under
        and behind it); the simulator still refuses any motion that would collide. Returns
        the path and the margin it keeps."""
        mind = self.context.mind
        radius = mind.config.robot_radius
        tries = ((self.squeeze_margin(), False), (radius, True))
        for margin, unknown in tries:
            try:
                path = plan_path(mind.grid, start, goal, margin, allow_unknown=unknown,
                                 comfort=radius)
            except MapError:
                continue
            if path.found:
                return path, margin
        # no path (the robot may stand where only a squeeze fits: a query from there with
        # the full radius is refused, which must not end the episode)
        return PathResult(PathStatus.NO_PATH, (), math.inf, 0), radius

    def squeeze_margin(self) -> float:
        """The slimmest margin a path may keep: the mind's own squeeze radius
        (`mind.squeeze_radius`), else the planning radius less `ExecutorConfig.squeeze`."""
        mind = self.context.mind
        slim = mind.config.squeeze_radius
        return mind.config.robot_radius - self.context.config.squeeze if slim is None else slim

    def _free_near(self, goal: Point, reach: float = 0.6) -> Point | None:
        """The traversable cell nearest to a blocked goal, within `reach` metres."""
        mind = self.context.mind
        grid = mind.grid
        free = grid.traversable(mind.config.robot_radius)
        cells = np.argwhere(free)
        if len(cells) == 0:
            return None
        points = grid.to_world(cells)
        d = np.linalg.norm(points - np.asarray(goal), axis=1)
        best = int(np.argmin(d))
        return (float(points[best, 0]), float(points[best, 1])) if d[best] <= reach else None


def _split_leg(waypoints: list[Point], step: float) -> tuple[list[Point], list[Point]]:
    """The waypoints of the first ~`step` metres of a path (the robot stands at the first),
    and the rest of the path from the leg's end."""
    leg: list[Point] = []
    budget = step
    for i, (a, b) in enumerate(zip(waypoints, waypoints[1:], strict=False)):
        length = math.dist(a, b)
        if length > budget:
            t = budget / length
            end = (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t)
            leg.append(end)
            return leg, [end, *waypoints[i + 1:]]
        leg.append((float(b[0]), float(b[1])))
        budget -= length
    return leg, leg[-1:]
