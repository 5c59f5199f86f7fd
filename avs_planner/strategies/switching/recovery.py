"""What the switching loop does when a CP call gives it no plan worth executing.

The main loop (`loop.py`) plans, executes, monitors and replans; this module holds its
remedies for when that rhythm breaks, so that each can be read (and tested) on its own:

- a CP result that is no good as it is: a call that hit its expansion limit is retried once
  in the CP's anytime mode (`Recovery.retry`, keeping the problem for `avs plan` if asked),
  and a plan worth less than it costs, R p(pi) < c(pi), worse than giving up by the CP's
  own objective, becomes "no plan above the threshold" (`Recovery.worth_it`);
- the steps taken before planning again, while the CP keeps timing out or no plan reaches
  the threshold: explore the nearest placeholder, drop a support label, look once more
  where the verification before a report missed a target the frames had confirmed,
  re-classify an uncertain room, doubt room categories believed certain, retry spots the
  base was blocked at. Each returns whether it did anything; the loop
  (`SwitchingLoop._recover`) decides their order, plans again after each, and gives up
  when none is left.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from avs_planner.cp.continual import ContinualPlanner
from avs_planner.cp.search import PlanResult, PlanStatus, PlanStep
from avs_planner.episode.executor import Executor
from avs_planner.episode.outcome import SearchResult
from avs_planner.episode.recall import check_spot
from avs_planner.episode.state_builder import StateBuilder
from avs_planner.episode.trace import Trace

if TYPE_CHECKING:
    from avs_planner.strategies.switching.loop import LoopConfig


class Recovery:
    """The switching loop's remedies (see the module's doc), over the loop's own state
    builder, executor, trace and settings."""

    def __init__(self, builder: StateBuilder, executor: Executor, trace: Trace,
                 config: LoopConfig) -> None:
        self.builder, self.executor, self.trace = builder, executor, trace
        self.config = config

    # ---- a CP result that is no good as it is -----------------------------------------------

    def worth_it(self, result: PlanResult) -> PlanResult:
        """The CP minimises c(pi) + R (1 - p(pi)); giving up costs R. A plan with
        R p(pi) < c(pi) is worse than giving up, by the planner's own objective, and is not
        executed: the result becomes "no plan above the threshold" (the loop then tries what
        it tries before giving up). Only plans that search what is already mapped are
        judged: a plan that explores is one chain of assumptions about what lies beyond a
        placeholder, while exploring also reveals every other room and object there, so its
        p(pi) undervalues it. For the same reason, when no such plan is worth its cost the
        robot explores the nearest placeholder left before it gives up
        (`SwitchingLoop._recover`)."""
        if not (self.config.worth_test and result.solved) or _explores(result.plan):
            return result
        value = self.config.reward * result.probability
        if value >= result.cost:
            return result
        self.trace.emit("belief", not_worth=[s.label for s in result.plan if not s.assumptive],
                        probability=round(result.probability, 5), cost=round(result.cost, 2),
                        reward=self.config.reward)
        return replace(result, status=PlanStatus.NO_PLAN_ABOVE_THRESHOLD, plan=(),
                       extra={**result.extra, "not_worth": True,
                              "best_probability": result.probability,
                              "best_cost": result.cost})

    def retry(self, planner: ContinualPlanner, result: PlanResult,
              record: SearchResult) -> PlanResult:
        """A CP call that ran out of time or nodes, retried once with the fallback settings
        (greedier, a larger expansion limit, anytime); counted in `record` as a call."""
        if not _timed_out(result):
            return result
        # a CP call that ran out of nodes is a call too: `plans` counts the `plan` events,
        # one per entry of `cp_time_s`
        record.plans += 1
        record.cp_times.append(result.planning_time_s)
        dumped = self.dump_problem(record.plans + 1)
        self.trace.emit("plan", why="timeout", status=result.status.value, plan=[],
                        planning_time_s=round(result.planning_time_s, 4), problem=dumped)
        options = planner.options
        cfg = self.config
        planner.options = replace(options, heuristic=cfg.fallback_heuristic,
                                  weight=cfg.fallback_weight,
                                  node_limit=cfg.fallback_node_limit,
                                  anytime=cfg.fallback_anytime)
        try:
            return planner.replan()
        finally:
            planner.options = options

    def dump_problem(self, number: int) -> str | None:
        """Keep a problem the CP could not solve in time (for `avs plan`), if asked to."""
        if self.config.dump_dir is None:
            return None
        path = Path(self.config.dump_dir) / f"timeout-{number}.pddl"
        path.write_text(self.builder.build().to_pddl(), encoding="utf-8")
        return str(path)

    # ---- steps before planning again ----------------------------------------------------------

    def visit_uncertain_room(self, visited: set[str]) -> bool:
        """No plan is good enough: the place classifier may have misled the room category
        beliefs (an elongated office reads as a corridor). Visit the places of the nearest
        room whose category is uncertain, once per room (`visited` grows), so it is
        classified again; only rooms that could still hold the target under some category
        (`could_hold`)."""
        certain = self.builder.certain_category
        room = self.executor.uncertain_room(certain, visited, self.builder.could_hold)
        if room is None:
            return False
        visited.add(room)
        self.trace.emit("action", action=f"(classify {room})", status="start")
        outcome = self.executor.visit_room(room)
        self.trace.emit("action", action=f"(classify {room})", status=outcome.status.value,
                        detail=outcome.detail, category=self.builder.category_belief(room))
        return True

    def recheck_unverified(self) -> bool:
        """No plan is good enough: look once more at a spot where frames confirmed the target
        and the verification before the report then missed it (`Mind.unverified`), from a
        standpoint that sees it, as a remembered sighting is checked (`recall.check_spot`).
        Confirmed, it is a known object again (the planner reports it, verifying first).
        The verification rejects phantoms, and a real object seen from the one spot it steps
        back to may be hidden by its shelf's side: in development office 345 a book the watch
        had confirmed was forgotten that way at 218 s and the robot gave up at 1097 s. Each
        spot once (it leaves the list)."""
        mind = self.executor.mind
        target = self.builder.task.target
        spot = next((u for u in mind.unverified if u[0] == target), None)
        if spot is None:
            return False
        mind.unverified.remove(spot)
        label, position = spot
        where = [round(v, 2) for v in position]
        self.trace.emit("action", action=f"(look-again {label})", status="start",
                        position=where)
        known, looked = check_spot(self.executor, label, position)
        self.trace.emit("action", action=f"(look-again {label})",
                        status="done" if looked else "failed", position=where,
                        detail=(f"seen again: {known.id}" if known is not None
                                else "not seen" if looked else "no way to a spot that sees it"))
        return True

    def doubt_categories(self) -> bool:
        """No plan is good enough and no uncertain room is left to look at again: the place
        classifier may be confidently wrong about a room (readings taken in an office's
        doorway see the corridor). Once per episode, rooms believed up to `doubt_category`
        become uncertain again, so the planner may assume another category for them (and
        `visit_uncertain_room` may re-classify them)."""
        doubt = self.config.doubt_category
        if not self.builder.doubt_categories(doubt):
            return False
        self.trace.emit("belief", doubt_categories=doubt, reason="no plan above the threshold")
        return True

    def retry_blocked(self) -> bool:
        """No plan is good enough while blocked spots are kept out of: try them again before
        giving up, at most `retry_blocked` times (each touch there widens the berth)."""
        gone = self.executor.mind.retry_blocked(self.config.retry_blocked)
        if not gone:
            return False
        self.trace.emit("belief", retry_blocked=[b.id for b in gone],
                        reason="no plan above the threshold")
        return True

    def shrink(self) -> bool:
        """Nothing to explore: plan with one support label fewer (a smaller problem)."""
        dropped = self.builder.drop_support()
        if dropped is None:
            return False
        self.trace.emit("belief", dropped_support=dropped, reason="planner timed out")
        return True

    def explore_instead(self) -> bool:
        """The CP ran out of time: drive to the nearest placeholder (more map, smaller
        uncertainty) and plan again. False if no placeholder is left."""
        target = self.executor.nearest_placeholder()
        if target is None:
            return False
        self.trace.emit("action", action=f"(explore {target})", status="start")
        outcome = self.executor.move(target, self.builder.build())
        self.trace.emit("action", action=f"(explore {target})", status=outcome.status.value,
                        detail=outcome.detail)
        return True


def _explores(plan: tuple[PlanStep, ...]) -> bool:
    """The plan drives to a placeholder or assumes what lies beyond one."""
    return any(s.name == "assume-leads-to-room" or
               (s.name == "move" and s.args[1].startswith("placeholder")) for s in plan)


def _timed_out(result: PlanResult) -> bool:
    """The CP call hit its expansion limit or its timeout."""
    return result.status in (PlanStatus.TIMEOUT, PlanStatus.NODE_LIMIT)
