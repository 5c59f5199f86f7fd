"""The continual planner as a unified-planning engine: `OneshotPlanner(name="avs")`, and
`AnytimePlanner(name="avs")` for the anytime schedule's improving plans.

Importing this module registers the engine (and with it UP's `replanner[avs]`) in UP's
default factory; `import avs_planner.up_engine` is enough. UP's model has no success
probabilities, so for plain UP problems every action succeeds (p = 1) and the objective is
the plan cost; pass `params={"success": {action_name: FNode}}` to plan with probabilities,
plus optionally `reward`, `weight`, `heuristic`, `node_limit`, `min_success`, `engine`
("auto", "native" or "python").
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import replace
from typing import IO, Any

import unified_planning as up
from unified_planning.engines import (
    Credits,
    Engine,
    PlanGenerationResult,
    PlanGenerationResultStatus,
)
from unified_planning.engines.mixins.anytime_planner import (
    AnytimeGuarantee,
    AnytimePlannerMixin,
)
from unified_planning.engines.mixins.oneshot_planner import (
    OneshotPlannerMixin,
    OptimalityGuarantee,
)
from unified_planning.environment import get_environment
from unified_planning.model import FNode, Problem, ProblemKind
from unified_planning.plans import ActionInstance, SequentialPlan

from avs_planner.cp.anytime import AnytimeRun
from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.planner import improving_plans, plan
from avs_planner.cp.search import PlanResult, PlanStatus, PlanStep, SearchOptions
from avs_planner.errors import PlanningError
from avs_planner.pddl.model import ProbabilisticProblem

ENGINE_NAME = "avs"

CREDITS = Credits(
    name="avs continual planner",
    author="avs-planner contributors",
    contact="see the avs-planner README",
    website="https://github.com/",
    license="MIT",
    short_description="Weighted A* on c + R(1 - p) with probabilistic h^max / FF, after "
    "Goebelbecker et al., \"A Planning Approach to Active Visual Search in Large Environments\".",
    long_description="Probabilistic continual planner after Goebelbecker et al.: grounds to "
    "bitsets, searches weighted A* on cost + R(1 - success probability).",
)

_STATUS = {
    PlanStatus.UNSOLVABLE: PlanGenerationResultStatus.UNSOLVABLE_PROVEN,
    PlanStatus.NO_PLAN_ABOVE_THRESHOLD: PlanGenerationResultStatus.UNSOLVABLE_INCOMPLETELY,
    PlanStatus.TIMEOUT: PlanGenerationResultStatus.TIMEOUT,
    PlanStatus.NODE_LIMIT: PlanGenerationResultStatus.UNSOLVABLE_INCOMPLETELY,
}


class AvsPlanner(Engine, OneshotPlannerMixin, AnytimePlannerMixin):
    """UP engine wrapper around `avs_planner.cp.planner.plan` (one-shot) and
    `improving_plans` (anytime: each plan better by the objective than the last, as the
    greedy search and then the weighted-A* restarts find it)."""

    def __init__(self, **params: Any):
        Engine.__init__(self)
        OneshotPlannerMixin.__init__(self)
        AnytimePlannerMixin.__init__(self)
        self._success: Mapping[str, FNode] = params.pop("success", {})
        self._options = SearchOptions(
            reward=float(params.pop("reward", SearchOptions.reward)),
            weight=float(params.pop("weight", SearchOptions.weight)),
            heuristic=str(params.pop("heuristic", "ff")),
            node_limit=params.pop("node_limit", None),
            min_success=float(params.pop("min_success", 0.0)),
            engine=str(params.pop("engine", "auto")),
            anytime=bool(params.pop("anytime", False)),
        )
        if params:
            raise up.exceptions.UPUsageError(f"unknown avs parameters: {sorted(params)}")
        self._options.check()

    @property
    def name(self) -> str:
        return ENGINE_NAME

    @staticmethod
    def get_credits(**kwargs: Any) -> Credits:
        return CREDITS

    @staticmethod
    def supported_kind() -> ProblemKind:
        kind = ProblemKind(version=2)
        kind.set_problem_class("ACTION_BASED")
        kind.set_typing("FLAT_TYPING")
        kind.set_typing("HIERARCHICAL_TYPING")
        for cond in ("NEGATIVE_CONDITIONS", "DISJUNCTIVE_CONDITIONS", "EQUALITIES",
                     "EXISTENTIAL_CONDITIONS", "UNIVERSAL_CONDITIONS"):
            kind.set_conditions_kind(cond)
        for effect in ("CONDITIONAL_EFFECTS", "FORALL_EFFECTS"):
            kind.set_effects_kind(effect)  # compiled away while grounding (cp/conditional.py)
        kind.set_initial_state("UNDEFINED_INITIAL_NUMERIC")  # a missing needed value is an error
        kind.set_quality_metrics("ACTIONS_COST")
        kind.set_quality_metrics("PLAN_LENGTH")
        for cost in ("STATIC_FLUENTS_IN_ACTIONS_COST", "INT_NUMBERS_IN_ACTIONS_COST",
                     "REAL_NUMBERS_IN_ACTIONS_COST"):
            kind.set_actions_cost_kind(cost)
        return kind

    @staticmethod
    def supports(problem_kind: ProblemKind) -> bool:
        return problem_kind <= AvsPlanner.supported_kind()

    @staticmethod
    def satisfies(optimality_guarantee: OptimalityGuarantee) -> bool:
        # optimal only when configured with an admissible heuristic at weight 1
        return optimality_guarantee == OptimalityGuarantee.SATISFICING

    def _solve(
        self,
        problem: up.model.AbstractProblem,
        heuristic: Callable[[up.model.state.State], float | None] | None = None,
        timeout: float | None = None,
        output_stream: IO[str] | None = None,
    ) -> PlanGenerationResult:
        assert isinstance(problem, Problem)
        options = replace(self._options, timeout_s=timeout)
        try:
            result = plan(ProbabilisticProblem(problem, self._success), options)
        except PlanningError as exc:
            return PlanGenerationResult(
                PlanGenerationResultStatus.UNSUPPORTED_PROBLEM, None, self.name,
                log_messages=[_log(str(exc))],
            )
        return self._to_up(problem, result, options)

    @staticmethod
    def ensures(anytime_guarantee: AnytimeGuarantee) -> bool:
        # every plan handed on is better by the objective than the one before
        return anytime_guarantee == AnytimeGuarantee.INCREASING_QUALITY

    def _get_solutions(
        self,
        problem: up.model.AbstractProblem,
        timeout: float | None = None,
        output_stream: IO[str] | None = None,
    ) -> Iterator[PlanGenerationResult]:
        """The anytime schedule's plans as it finds them (status INTERMEDIATE), then, when
        it found none, one result saying why; `timeout` bounds the whole run."""
        assert isinstance(problem, Problem)
        options = replace(self._options, timeout_s=timeout, anytime=True)
        run = AnytimeRun()
        try:
            for result in improving_plans(ProbabilisticProblem(problem, self._success),
                                          options, run):
                yield PlanGenerationResult(
                    PlanGenerationResultStatus.INTERMEDIATE,
                    to_up_plan(problem, result.plan), self.name, _metrics(result))
        except PlanningError as exc:
            yield PlanGenerationResult(PlanGenerationResultStatus.UNSUPPORTED_PROBLEM, None,
                                       self.name, log_messages=[_log(str(exc))])
            return
        if not run.best.solved:
            final = run.result(options)
            yield PlanGenerationResult(_STATUS[final.status], None, self.name, _metrics(final))

    def _to_up(self, problem: Problem, result: PlanResult, options) -> PlanGenerationResult:
        metrics = _metrics(result)
        if not result.solved:
            return PlanGenerationResult(_STATUS[result.status], None, self.name, metrics)
        optimal = (get_heuristic(options.heuristic).admissible and options.weight == 1.0
                   and result.stopped_by is None and not options.anytime)
        status = (
            PlanGenerationResultStatus.SOLVED_OPTIMALLY if optimal
            else PlanGenerationResultStatus.SOLVED_SATISFICING
        )
        return PlanGenerationResult(status, to_up_plan(problem, result.plan), self.name, metrics)


def _metrics(result: PlanResult) -> dict[str, str]:
    return {
        "engine_internal_time": str(result.planning_time_s),
        "expanded": str(result.expanded),
        "probability": str(result.probability),
        "objective": str(result.objective),
    }


def _log(message: str) -> up.engines.LogMessage:
    return up.engines.LogMessage(up.engines.LogLevel.ERROR, message)


def to_up_plan(problem: Problem, steps: tuple[PlanStep, ...] | list[PlanStep]) -> SequentialPlan:
    """Our plan steps as a UP `SequentialPlan` over `problem`'s actions and objects."""
    instances = [
        ActionInstance(problem.action(step.name), [problem.object(a) for a in step.args])
        for step in steps
    ]
    return SequentialPlan(instances, problem.environment)


def register(environment: up.environment.Environment | None = None) -> None:
    """Add the engine to the factory (idempotent)."""
    factory = (environment or get_environment()).factory
    if ENGINE_NAME not in factory.engines:
        factory.add_engine(ENGINE_NAME, __name__, AvsPlanner.__name__)


register()
