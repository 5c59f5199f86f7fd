"""The probabilistic planning task: a unified-planning `Problem` plus success probabilities.

This is the contract between the PDDL reader (which builds it) and the planners (which ground
and search it). An action `a` with effect `(probabilistic P E)` becomes, in `problem`, an action
whose effect is `E` (what happens when it succeeds), and `success[a.name]` holds `P` as a UP
real-valued expression over `a`'s parameters (a constant, or static numeric fluents whose
values the problem's `:init` gives). Actions with no entry succeed with probability 1.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction

from unified_planning.model import FNode, Problem

from avs_planner.pddl.diagnostics import Diagnostic

ASSUMPTIVE_PREFIX = "assume-"


@dataclass(frozen=True)
class ProbabilisticProblem:
    """A UP problem whose actions succeed with probability `success[name]` (default 1)."""

    problem: Problem
    success: Mapping[str, FNode] = field(default_factory=dict)
    domain_file: str = "<domain>"
    problem_file: str = "<problem>"
    # What the reader accepted or repaired (undeclared requirements, shared names, ...)
    warnings: tuple[Diagnostic, ...] = ()

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
