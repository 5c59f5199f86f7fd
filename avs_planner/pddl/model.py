"""The probabilistic planning task: a planning model plus success probabilities.

This is the contract between the PDDL reader (which builds it) and the planners (which ground
and search it). An action `a` with effect `(probabilistic P E)` becomes, in `model`, an action
whose effect is `E` (what happens when it succeeds), and `success[a.name]` holds `P` as a
real-valued expression of the model over `a`'s parameters (a constant, or static numeric
fluents whose values the problem's `:init` gives). Actions with no entry succeed with
probability 1.

The model is a unified-planning (UP) `Problem`, or, as the reader builds it where it can, the
project's own `lite.Problem`, which offers the part of UP's model API the planner reads (the
same names and methods: `actions`, `fluents`, `all_objects`, `explicit_initial_values`,
`goals`, `quality_metrics`; nodes with `is_and()`, `args`, `fluent()`, ...; effects with
`fluent`, `value`, `condition`, `forall`), without importing UP. `success` holds nodes of the
model's kind. Whoever needs UP objects (UP's engines and plan validators) asks for `problem`
and `up_success`: the model itself if it is UP's, else UP's problem of the same text (or,
for a problem the episode builds from a state, of the same state), built once when first
asked. The episode builds its problems in the domain's model (`episode/domain.py`), so a
search episode does not import UP.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from avs_planner.errors import SourcePosition
from avs_planner.pddl import lite
from avs_planner.pddl.diagnostics import Diagnostic

if TYPE_CHECKING:
    from unified_planning.model import FNode, Problem

ASSUMPTIVE_PREFIX = "assume-"


@dataclass(frozen=True)
class SourceMap:
    """Where the reader found each action, each derived predicate's rules and the goal, so
    that what the grounder refuses is named with FILE:LINE:COL (a task built in
    unified-planning directly has none)."""

    actions: Mapping[str, SourcePosition] = field(default_factory=dict)  # by lower-case name
    goal: SourcePosition | None = None  # the :goal's formula
    goal_parts: tuple[SourcePosition, ...] = ()  # its conjuncts, nested `and`s flattened
    rules: Mapping[str, SourcePosition] = field(default_factory=dict)
    """Per derived predicate (lower-case), its first `(:derived ...)` rule."""

    def action(self, name: str) -> SourcePosition | None:
        return self.actions.get(name.lower())

    def rule(self, name: str) -> SourcePosition | None:
        return self.rules.get(name.lower())

    def goal_part(self, index: int, count: int) -> SourcePosition | None:
        """Conjunct `index` of `count` (as the grounder flattens the goal): its own position
        when the text has as many conjuncts, else the goal's."""
        if count == len(self.goal_parts) and 0 <= index < count:
            return self.goal_parts[index]
        return self.goal


@dataclass(frozen=True)
class ProbabilisticProblem:
    """A problem whose actions succeed with probability `success[name]` (default 1)."""

    model: Problem | lite.Problem  # what the planner grounds; see the module's docstring
    success: Mapping[str, Any] = field(default_factory=dict)  # nodes of the model's kind
    domain_file: str = "<domain>"
    problem_file: str = "<problem>"
    # What the reader accepted or repaired (undeclared requirements, shared names, ...)
    warnings: tuple[Diagnostic, ...] = ()
    sources: SourceMap = field(default_factory=SourceMap)
    # What the reader's checks found that the planner cannot ground (the reader still reads
    # it, as unified-planning does); the planner refuses the first, at its position
    not_grounded: tuple[Diagnostic, ...] = ()

    @property
    def problem(self) -> Problem:
        """The UP problem: the model, or UP's problem of the text the model was read from
        (built when first asked; this imports UP)."""
        if lite.is_lite(self.model):
            return self.model.to_up()[0]  # type: ignore[union-attr]
        return self.model  # type: ignore[return-value]

    @property
    def up_success(self) -> Mapping[str, FNode]:
        """`success` as UP expressions of `problem`."""
        if lite.is_lite(self.model):
            return self.model.to_up()[1]  # type: ignore[union-attr]
        return self.success

    def is_assumptive(self, action_name: str) -> bool:
        """Assumptive actions only set beliefs; the executor does not run them, it watches them."""
        return action_name.lower().startswith(ASSUMPTIVE_PREFIX)

    def constant_success(self, action_name: str) -> Fraction | None:
        """The action's success probability if it is a constant, else None (fluent-valued)."""
        expr = self.success.get(action_name)
        if expr is None:
            return Fraction(1)
        if expr.is_constant():
            return Fraction(str(expr.constant_value()))
        return None
