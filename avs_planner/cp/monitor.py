"""Execution monitoring: is the rest of a plan still good in the current state, and if not, why.

Checks, step by step from the current state: the action still exists in the (re)grounded task
and its preconditions hold (for an assumptive action a failure means the assumption was
contradicted), its success probability moved by no more than a threshold, and the goal holds
at the end.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum

from avs_planner.cp.search import PlanStep
from avs_planner.cp.task import GroundAction, GroundTask, atom_str

DEFAULT_PROBABILITY_THRESHOLD = 0.1


class MonitorStatus(Enum):
    VALID = "valid"
    PRECONDITION_FAILED = "precondition_failed"
    ASSUMPTION_CONTRADICTED = "assumption_contradicted"
    PROBABILITY_CHANGED = "probability_changed"
    GOAL_NOT_REACHED = "goal_not_reached"


@dataclass(frozen=True)
class MonitorReport:
    """Verdict on the rest of a plan; `step` is the index of the first bad step, if any."""

    status: MonitorStatus
    step: int | None = None
    action: str | None = None
    detail: str = ""
    failed: tuple[str, ...] = field(default_factory=tuple)
    probability: float = 1.0
    # (label, probability in this state) of each assumptive step checked, in plan order (0.0
    # for a contradicted one): what the assumption ledger (`reporting.explain`) records
    assumptions: tuple[tuple[str, float], ...] = ()

    @property
    def valid(self) -> bool:
        return self.status is MonitorStatus.VALID


def _failed_conditions(action: GroundAction, task: GroundTask, state: int) -> tuple[str, ...]:
    facts = task.facts
    out = [atom_str(facts[i]) for i in action.pre_facts if not state >> i & 1]
    out += [f"(not {atom_str(facts[i])})" for i in range(len(facts))
            if action.pre_neg >> i & 1 and state >> i & 1]
    for pos, neg in action.clauses:
        if not (state & pos or neg & ~state):
            out.append("(or ...)")
    return tuple(out)


def monitor(
    plan: Sequence[PlanStep],
    task: GroundTask,
    state: int | None = None,
    threshold: float = DEFAULT_PROBABILITY_THRESHOLD,
) -> MonitorReport:
    """Check `plan` (the steps still to execute) from `state` (default: `task.init`)."""
    current = task.init if state is None else task.close(state)
    probability = 1.0
    assumed: list[tuple[str, float]] = []
    for i, step in enumerate(plan):
        action = task.action_in(step.name, step.args, current)
        if action is None or not action.applicable(current):
            if step.assumptive:
                assumed.append((step.label, 0.0))
            return _broken(i, step, action, task, current, tuple(assumed))
        if step.assumptive:
            assumed.append((step.label, action.probability))
        if abs(action.probability - step.probability) > threshold:
            kind = "assumption" if step.assumptive else "action"
            return MonitorReport(
                MonitorStatus.PROBABILITY_CHANGED, i, step.label,
                f"{kind} probability changed from {step.probability:.3g} "
                f"to {action.probability:.3g}", assumptions=tuple(assumed),
            )
        probability *= action.probability
        current = task.successor(action, current)  # derived facts included
    if not task.is_goal(current):
        return MonitorReport(MonitorStatus.GOAL_NOT_REACHED, len(plan), None,
                             "the plan no longer reaches the goal", assumptions=tuple(assumed))
    return MonitorReport(MonitorStatus.VALID, probability=probability, assumptions=tuple(assumed))


def _broken(i: int, step: PlanStep, action, task: GroundTask, state: int,  # noqa: ANN001
            assumed: tuple[tuple[str, float], ...] = ()) -> MonitorReport:
    status = (
        MonitorStatus.ASSUMPTION_CONTRADICTED if step.assumptive
        else MonitorStatus.PRECONDITION_FAILED
    )
    if action is None:
        return MonitorReport(status, i, step.label,
                             "no longer possible (unreachable or probability 0)",
                             probability=0.0, assumptions=assumed)
    failed = _failed_conditions(action, task, state)
    return MonitorReport(status, i, step.label, "fails: " + " ".join(failed), failed,
                         probability=0.0, assumptions=assumed)
