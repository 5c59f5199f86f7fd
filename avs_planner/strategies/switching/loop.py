"""The switching loop of the active visual search paper (Göbelbecker et al.): plan with
assumptions, execute, monitor, replan, give up.

Assumptive steps stay in the plan and are re-checked by the monitor against every new belief
state; physical and sensing steps are executed and removed. The CP replans when the monitor
reports a broken plan (a placeholder explored, a search rejected, a probability moved) and the
episode gives up when no plan reaches the success threshold.

This module holds the loop and its settings (`LoopConfig`); what it does when a CP call gives
it no plan worth executing (the anytime retry, the worth test, exploring, re-classifying,
doubting categories, retrying blocked spots) is `recovery.py`'s, re-exported here where the
loop's tests and callers knew it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from avs_planner.cp.continual import ContinualPlanner, Decision
from avs_planner.cp.search import DEFAULT_REWARD, PlanResult, PlanStep, SearchOptions
from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.executor import Executor, ExecutorConfig
from avs_planner.episode.outcome import Outcome, SearchResult, StepOutcome, StepStatus
from avs_planner.episode.state_builder import AvsState, BuilderConfig, StateBuilder
from avs_planner.episode.trace import Trace
from avs_planner.strategies.switching.recovery import Recovery, _timed_out
from avs_planner.strategies.switching.recovery import _explores as _explores  # re-exported
from avs_planner.strategies.switching.stopping import Remaining, look_cost, remaining


@dataclass(frozen=True)
class LoopConfig:
    """Planner settings and budgets (simulated seconds, wall seconds, executed steps).
    Defaults whose comments cite episodes were chosen on development worlds and seeds
    (generated buildings below seed 10000, Fig. 3 noise seeds 0-99), never on the held-out
    range (docs/experiments.md); R and the costs are the paper's."""

    # R: what finding the object is worth, in the robot's seconds: the CP's goal reward and
    # the DT's terminal penalties (`executor_config`); the paper's value
    reward: float = DEFAULT_REWARD
    weight: float = 3.0
    heuristic: str = "hadd"  # on these problems far fewer expansions than ff
    min_success: float = 0.01
    # the CP stops after this many expansions (deterministic for a seed, whatever the load)
    # or this many seconds (a safety net); either counts as "timed out" below
    cp_node_limit: int = 4000
    cp_timeout_s: float = 20.0
    # a search that hit the limit is retried once in the CP's anytime mode (LAMA's schedule:
    # greedy best-first with FF and helpful actions, then weighted A* restarts on the
    # objective), each phase under `fallback_node_limit` expansions. On generated office
    # worlds the single FF w=5 retry this replaces found no plan within 20000 expansions on
    # most problems the first search timed out on, and the robot explored blindly instead;
    # the anytime schedule solved them (or proved no plan reaches the threshold)
    fallback_heuristic: str = "ff"
    fallback_weight: float = 5.0
    fallback_node_limit: int = 30000
    fallback_anytime: bool = True
    time_budget_s: float = 1200.0
    wall_budget_s: float = 600.0
    max_steps: int = 120
    dump_dir: str | None = None  # write problems the CP timed out on here
    # before giving up, room categories believed below this are doubted once (see
    # SwitchingLoop._doubt_categories); the state builder's own threshold is 0.9
    doubt_category: float = 0.999
    # the detector looks for the target as the robot drives (Executor.watch); False searches
    # only through the DT's view cones, as the active visual search paper's system did
    watch: bool = True
    # blocked spots are tried again this many times when nothing else is left
    retry_blocked: int = 2
    # a plan that searches only what is already mapped (no placeholder explored, no room
    # assumed beyond one) is executed only if it is worth more than it costs: reward x
    # P(success) > cost, the CP's own objective against giving up (see `_worth_it`)
    worth_test: bool = True
    # frames taken in passing are evidence, and supports they show become known objects
    # (`Executor.enable_glimpses`, `episode/glimpses.py`)
    glimpses: bool = True
    # directions the detector looks in at each new place (`Executor.look_around`)
    look_headings: int = 6
    # of those, only the ones whose frame is worth its time (`ExecutorConfig.look_by_value`)
    look_by_value: bool = True
    # every frame also asks for furniture that tells a room's kind, kept when the frames
    # that had its spot in view mostly showed it (`episode/landmarks.py`)
    landmarks: bool = True
    # price moves and searches in the robot's own seconds (`BuilderConfig.seconds`), the
    # unit R is in (docs/results.md, "Development worlds, 2026-11-28: a building's rate")
    seconds: bool = True
    # give up when no continuation is worth its cost against the building-level belief
    # (`stopping.py`), not only when no single plan reaches the threshold
    stop_rule: bool = True
    # predict what lies behind placeholders with the building's own outcomes so far
    # (`conceptual_map/conceptual/calibration.py`; measured always, used only when on)
    calibrate_placeholders: bool = False

    def executor_config(self, base: ExecutorConfig | None = None) -> ExecutorConfig:
        """The executor's settings these loop settings decide (R, the watch, glimpses, the
        look around, room landmarks), over `base`: the episode builds its executor with them
        once."""
        return replace(base or ExecutorConfig(), miss_penalty=self.reward, watch=self.watch,
                       glimpses=self.glimpses, look_headings=self.look_headings,
                       look_by_value=self.look_by_value and self.glimpses,
                       landmarks=self.landmarks)

    def builder_config(self, base: BuilderConfig | None = None) -> BuilderConfig:
        """The state builder's settings these loop settings decide (costs in seconds)."""
        return replace(base or BuilderConfig(), seconds=self.seconds)

    def configured(self, executor: Executor, builder: StateBuilder) -> list[str]:
        """The settings `executor` and `builder` were built with that differ from what
        these loop settings decide (empty when they were built from them)."""
        pairs = [(executor.config, self.executor_config(executor.config)),
                 (builder.config, self.builder_config(builder.config))]
        return [f"{f}={getattr(have, f)!r} (the loop's settings say {getattr(want, f)!r})"
                for have, want in pairs for f in (x.name for x in fields(have))
                if getattr(have, f) != getattr(want, f)]


class SwitchingLoop:
    """Owns the continual planner; asks the executor to run each non-assumptive step."""

    def __init__(self, builder: StateBuilder, executor: Executor, trace: Trace,
                 config: LoopConfig | None = None, should_stop: Any = None):
        self.builder, self.executor, self.trace = builder, executor, trace
        self.config = config or LoopConfig()
        differ = self.config.configured(executor, builder)
        if differ:
            raise EpisodeError("the executor and state builder must be built with the loop's "
                               "settings (`LoopConfig.executor_config`, `builder_config`): "
                               + "; ".join(differ))
        self.should_stop = should_stop or (lambda: False)
        builder.mind.cmap.calibration.apply = self.config.calibrate_placeholders
        self.result = SearchResult(Outcome.GAVE_UP, "")
        self.planner: ContinualPlanner | None = None
        self.start_clock = executor.robot.clock
        self.visited_rooms: set[str] = set()
        # (action, belief state) pairs that failed: never executed again (a guard; the state
        # builder already withholds a failed move until something new is learned)
        self.failed: set[tuple[str, int]] = set()

    def run(self) -> SearchResult:
        self.executor.look_around()
        state = self.builder.build()
        self.planner = ContinualPlanner(state.skeleton(), self._options(),
                                        min_success=self.config.min_success)
        first = self._fallback(self.planner.replan(state.world_state()))
        self._record_plan(first, "initial")
        first = self._recover(first)
        stop = self._budget_spent()
        if stop:
            return self._end(Outcome.TIMEOUT, stop)
        if first is None:
            return self._end(Outcome.GAVE_UP, "planner timed out, nothing to explore")
        if not first.solved:
            return self._end(Outcome.GAVE_UP, self._no_plan(first))
        for _ in range(self.config.max_steps):
            stop = self._budget_spent()
            if stop:
                return self._end(Outcome.TIMEOUT, stop)
            hopeless = self._hopeless()
            if hopeless:
                return self._end(Outcome.GAVE_UP, hopeless)
            index = next((i for i, s in enumerate(self.planner.plan) if not s.assumptive), None)
            if index is None:
                return self._end(Outcome.GAVE_UP, "plan has no executable step")
            step = self.planner.plan[index]
            tried = (step.label, _signature(state))
            if tried in self.failed:
                return self._end(Outcome.GAVE_UP, f"{step.label} failed from this very state "
                                 f"before and nothing new was learned since")
            clock = self.executor.robot.clock
            outcome = self._execute(step, state)
            if outcome.status is StepStatus.FAILED:
                self.failed.add(tried)
            if outcome.status is StepStatus.FOUND:
                self.result.found = outcome.reported
                return self._end(Outcome.FOUND, outcome.detail)
            self.planner.plan = self.planner.plan[:index] + self.planner.plan[index + 1:]
            state = self.builder.build()
            if self.executor.robot.clock == clock and _signature(state) == tried[1]:
                self._no_effect(step, tried)
                state = self.builder.build()  # without the withheld move
            settled = step.label if _search_rejected(step, outcome) else None
            result = self._monitor(state, outcome, settled)
            if result is not None:
                result = self._recover(result)
                stop = self._budget_spent()
                if stop:
                    return self._end(Outcome.TIMEOUT, stop)
                if result is None:
                    return self._end(Outcome.GAVE_UP, "planner timed out, nothing to explore")
                state = self.builder.build()
            if result is not None and not result.solved:
                return self._end(Outcome.GAVE_UP, self._no_plan(result))
        return self._end(Outcome.TIMEOUT, f"{self.config.max_steps} steps executed")

    def _no_effect(self, step: PlanStep, tried: tuple[str, int]) -> None:
        """The step took no time and left the belief state as it was: planned again from
        that state it would do nothing again, as often as the CP asked (a move between two
        places that ended where it began was replanned 85 times at one simulated instant).
        Like a failed step it is evidence: never executed again from this state, and a move
        is withheld from the plan's topology until something new is learned."""
        self.failed.add(tried)
        if step.name == "move":
            self.executor.mind.move_failed(step.args[1])
        self.trace.emit("belief", no_effect=step.label,
                        reason="took no time and changed nothing the planner sees")

    def _fallback(self, result: PlanResult) -> PlanResult:
        """A search that ran out of time is retried with the fallback heuristic, greedier
        and with a larger expansion limit; a plan worth less than it costs is none."""
        return self._worth_it(self._retry(result))

    def _hopeless(self) -> str | None:
        """Why going on is worse than giving up by the building-level belief
        (`stopping.remaining`), or None while some continuation is worth its cost."""
        if not self.config.stop_rule:
            return None
        belief = self._remaining()
        if belief.worth_going_on(self.config.reward):
            return None
        best = belief.best(self.config.reward)
        self.trace.emit("belief", p_unsearched=round(belief.p, 5), options=len(belief.options),
                        best=None if best is None else
                        {"kind": best.kind, "name": best.name, "p": round(best.p, 5),
                         "cost": round(best.cost, 2)},
                        reward=self.config.reward)
        return belief.describe(self.config.reward)

    def _no_plan(self, result: PlanResult) -> str:
        """Why the episode gives up, in words."""
        hopeless = result.extra.get("hopeless") or self._hopeless()
        if hopeless:
            return hopeless
        if result.extra.get("not_worth"):
            return (f"no plan is worth its cost: the best left finds the target with "
                    f"p={result.extra['best_probability']:.3g} at cost "
                    f"{result.extra['best_cost']:.0f} (reward {self.config.reward:g} x p < cost)")
        return (f"no plan above the success threshold {self.config.min_success:g} "
                f"({result.status.value})")

    def _options(self) -> SearchOptions:
        cfg = self.config
        # the success threshold bounds the search, it does not filter its result: the best
        # plan by c + R(1 - p) may be a cheap hopeless one (search the kitchen table for a
        # stapler, p = 0.008, cost 12) while exploring finds it with p = 0.07; filtered
        # afterwards, that read as "no plan above the threshold" and the robot gave up 27 s
        # into a building it had not explored (generated office 3, stapler)
        return SearchOptions(reward=cfg.reward, weight=cfg.weight, heuristic=cfg.heuristic,
                             node_limit=cfg.cp_node_limit, timeout_s=cfg.cp_timeout_s,
                             min_success=cfg.min_success)

    def _execute(self, step: PlanStep, state: AvsState) -> StepOutcome:
        self.trace.emit("action", action=step.label, status="start")
        outcome = self.executor.run(step, state, assumed_categories(self.planner.plan))
        self.trace.emit("action", action=step.label, status=outcome.status.value,
                        detail=outcome.detail)
        return outcome

    def _recover(self, result: PlanResult) -> PlanResult | None:
        """While the CP times out, explore (or shrink the problem) and plan again; when no
        plan reaches the threshold, first look again at rooms whose category is uncertain.
        None when the CP timed out and nothing is left to explore."""
        while True:
            if self._budget_spent():
                return result  # the main loop ends the episode on its next step
            while _timed_out(result):
                if self._budget_spent() or (not self._explore_instead() and not self._shrink()):
                    return None
                result = self._plan_again("after exploring")
            if result.solved:
                return result
            hopeless = self._hopeless()
            if hopeless:  # the caller gives up, naming the probability left
                return replace(result, extra={**result.extra, "hopeless": hopeless})
            if result.extra.get("not_worth") and self._explore_instead():
                # nothing on the mapped part is worth searching, but exploring is worth
                # more than the one chain of assumptions a plan puts on it (`_worth_it`)
                result = self._plan_again("after exploring: nothing mapped was worth its cost")
            elif self._remedies().recheck_unverified():
                result = self._plan_again("after looking again where the target was seen")
            elif self._visit_uncertain_room():
                result = self._plan_again("after visiting an uncertain room")
            elif self._doubt_categories():
                result = self._plan_again("doubting room categories believed certain")
            elif self._retry_blocked():
                result = self._plan_again("retrying spots the base was blocked at")
            else:
                return result

    def _plan_again(self, why: str) -> PlanResult:
        """One CP call on the current beliefs (there is no plan left to monitor)."""
        assert self.planner is not None
        state = self.builder.build()
        self.planner.pproblem = state.skeleton()
        result = self._fallback(self.planner.replan(state.world_state()))
        self._record_plan(result, why)
        return result

    # ---- the remedies (`recovery.py`), as the loop's own steps ---------------------------------

    def _remedies(self) -> Recovery:
        """The remedies over the loop's current state builder, executor, trace and settings."""
        return Recovery(self.builder, self.executor, self.trace, self.config)

    def _worth_it(self, result: PlanResult) -> PlanResult:
        """A mapped-only plan worth less than it costs becomes none (`Recovery.worth_it`)."""
        return self._remedies().worth_it(result)

    def _retry(self, result: PlanResult) -> PlanResult:
        """A timed-out CP call, retried once in anytime mode (`Recovery.retry`)."""
        assert self.planner is not None
        return self._remedies().retry(self.planner, result, self.result)

    def _visit_uncertain_room(self) -> bool:
        """Re-classify the nearest uncertain room (`Recovery.visit_uncertain_room`)."""
        return self._remedies().visit_uncertain_room(self.visited_rooms)

    def _doubt_categories(self) -> bool:
        """Once, doubt categories believed certain (`Recovery.doubt_categories`)."""
        return self._remedies().doubt_categories()

    def _retry_blocked(self) -> bool:
        """Try blocked spots again (`Recovery.retry_blocked`)."""
        return self._remedies().retry_blocked()

    def _shrink(self) -> bool:
        """Plan with one support label fewer (`Recovery.shrink`)."""
        return self._remedies().shrink()

    def _explore_instead(self) -> bool:
        """Drive to the nearest placeholder (`Recovery.explore_instead`)."""
        return self._remedies().explore_instead()

    def _monitor(self, state: AvsState, outcome: StepOutcome,
                 settled: str | None = None) -> PlanResult | None:
        """Hand the new belief state to the CP: None if the plan stands, else the new plan.

        `settled`: the step (a search) the DT just rejected, if it was one. The plan was made
        betting on that search (its success a probabilistic effect; the plan may even hold a
        second search of the same location, planned as an independent try); now the DT has
        looked through the cones and the map holds what it saw, so the rest of the plan is
        re-decided on that evidence instead of kept while its probabilities move by less than
        the monitor's threshold."""
        assert self.planner is not None
        update = self.planner.update(state.world_state(), state.skeleton(),
                                     observed=outcome.observed or None)
        if update.matched:
            self.trace.emit("belief", matched=dict(update.matched))
        report = update.report
        self.trace.emit("monitor", verdict=report.status.value if report else "",
                        confirmed=list(update.confirmed),
                        assumptions={a: round(p, 5) for a, p in report.assumptions}
                        if report else {})
        if update.decision is Decision.CONTINUE and settled:
            self.trace.emit("replan", status="search_settled", action=settled,
                            detail="the DT rejected it: the plan is re-decided on what it saw")
            self.result.replans += 1
            result = self._fallback(self.planner.replan(state.world_state()))
            self._record_plan(result, "replan")
            return result
        if update.decision is Decision.CONTINUE:
            return None
        report = update.report
        self.trace.emit("replan", status=report.status.value if report else "",
                        action=report.action if report else None,
                        detail=report.detail if report else "")
        self.result.replans += 1
        assert update.result is not None
        result = self._fallback(update.result)
        self._record_plan(result, "replan")
        return result

    def _record_plan(self, result: PlanResult, why: str) -> None:
        self.result.plans += 1
        self.result.cp_times.append(result.planning_time_s)
        self.trace.emit("plan", why=why, status=result.status.value,
                        plan=[s.label for s in result.plan],
                        step_p=[round(s.probability, 5) for s in result.plan],
                        assumptive=[i for i, s in enumerate(result.plan) if s.assumptive],
                        probability=round(result.probability, 5), cost=round(result.cost, 2),
                        planning_time_s=round(result.planning_time_s, 4),
                        expanded=result.expanded, p_unsearched=self._p_unsearched())

    def _p_unsearched(self) -> float | None:
        """The building-level belief that the target is still to be found (for the trace)."""
        if not self.config.stop_rule:
            return None
        return round(self._remaining().p, 5)

    def _remaining(self) -> Remaining:
        ex = self.executor
        return remaining(ex.mind, self.builder, ex.robot.pose[:2],
                         look_cost(ex.mind.body, ex.config.look_headings))

    def _budget_spent(self) -> str | None:
        cfg = self.config
        if self.should_stop():
            return "stopped on request"
        if self.executor.robot.clock - self.start_clock > cfg.time_budget_s:
            return f"simulated time budget {cfg.time_budget_s:g} s spent"
        if self.trace.wall > cfg.wall_budget_s:
            return f"wall time budget {cfg.wall_budget_s:g} s spent"
        return None

    def _end(self, outcome: Outcome, reason: str) -> SearchResult:
        if outcome is Outcome.GAVE_UP:
            left = self._p_unsearched()
            if left is not None and "space not yet searched" not in reason:
                reason += f"; P(target in space not yet searched) = {left:.3g}"
            reason += self._cut_off()
        self.result.outcome, self.result.reason = outcome, reason
        self.trace.emit("done", outcome=outcome.value, reason=reason)
        return self.result


    def _cut_off(self) -> str:
        """What the robot's body keeps it from: blocked doors and openings too narrow."""
        mind = self.executor.mind
        notes = [b.describe() for b in mind.blockages.seen.values()]
        notes += [o.describe(mind.passing_width)
                  for o in mind.narrow_openings(self.executor.robot.pose[:2])]
        if notes:
            self.trace.emit("belief", cut_off=notes)
        return f"; unreachable: {'; '.join(notes)}" if notes else ""


def _signature(state: AvsState) -> int:
    """The belief state as the CP sees it (atoms and numbers)."""
    return hash((state.atoms, frozenset(state.values.items())))


def _search_rejected(step: PlanStep, outcome: StepOutcome) -> bool:
    """A SEARCHFOROBJECT that ran and whose DT session rejected the location."""
    return step.name.startswith("searchforobject") and outcome.status is StepStatus.DONE \
        and outcome.detail.startswith("rejected")


def assumed_categories(plan: tuple[PlanStep, ...] | list[PlanStep]) -> dict[str, str]:
    """Room -> category the plan's assumptions give it (ASSUME-CATEGORY, -LEADS-TO-ROOM)."""
    out: dict[str, str] = {}
    for step in plan:
        if step.name == "assume-category":
            out[step.args[0]] = step.args[1]
        elif step.name == "assume-leads-to-room":
            out[step.args[2]] = step.args[1]
    return out
