"""Lifted action schemas compiled from a problem (UP's model or the project's own, `pddl.lite`,
read through the methods both have) into plain tuples the grounder joins over.

Terms are strings: a parameter is `?name`, anything else is an object name. Numeric
expressions (action costs, success probabilities) become `encoding.VectorExpr`s, evaluated
for many bindings at once from the numeric values of the state.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from avs_planner.cp.conditional import CondEffect, compile_effect
from avs_planner.cp.encoding import VectorExpr, compile_vector
from avs_planner.cp.encoding import term as _term
from avs_planner.cp.formulas import unsupported_condition
from avs_planner.cp.unsupported import in_action
from avs_planner.errors import PlanningError
from avs_planner.pddl import lite
from avs_planner.pddl.model import ProbabilisticProblem

if TYPE_CHECKING:
    from unified_planning.model import Action, FNode, InstantaneousAction, Problem, Type

Term = str
AtomTemplate = tuple[str, ...]  # (predicate, term, ...)


@dataclass(frozen=True)
class LiftedSchema:
    """One action (or a derived predicate's rule: `derives`): parameters with their types,
    conditions split static/dynamic, effects."""

    name: str
    params: tuple[str, ...]
    param_types: tuple[Type, ...]
    static_pos: tuple[AtomTemplate, ...]
    static_neg: tuple[AtomTemplate, ...]
    pre_pos: tuple[AtomTemplate, ...]
    pre_neg: tuple[AtomTemplate, ...]
    equal: tuple[tuple[Term, Term], ...]
    not_equal: tuple[tuple[Term, Term], ...]
    add: tuple[AtomTemplate, ...]
    delete: tuple[AtomTemplate, ...]
    cost: VectorExpr
    probability: VectorExpr
    complex: tuple[FNode, ...] = ()
    never: bool = False
    conditional: tuple[CondEffect, ...] = ()
    derives: str = ""
    """A derived predicate's rule (`axioms.py`), not an action: the predicate (`add` holds
    its head, the conditions its body); rules are grounded like actions."""
    stratum: int = 0  # a rule's stratum (`pddl.stratify`)

    @property
    def is_rule(self) -> bool:
        return bool(self.derives)

    @property
    def what(self) -> str:
        """How messages name it: `action NAME`, or `derived predicate NAME` for a rule."""
        return f"derived predicate {self.derives}" if self.derives else f"action {self.name}"


def atom_template(node: FNode) -> AtomTemplate:
    """`(pred ?x obj)` of a boolean fluent expression."""
    return (node.fluent().name, *(_term(a) for a in node.args))


def _conjuncts(node: FNode) -> list[FNode]:
    if node.is_and():
        return [c for arg in node.args for c in _conjuncts(arg)]
    return [node]


def _split_preconditions(action: InstantaneousAction, static: set[str]) -> dict[str, list]:
    parts: dict[str, list] = {
        k: [] for k in ("sp", "sn", "dp", "dn", "eq", "ne", "never", "complex")
    }
    for cond in (c for pre in action.preconditions for c in _conjuncts(pre)):
        negated = cond.is_not()
        inner = cond.arg(0) if negated else cond
        if inner.is_fluent_exp() and inner.fluent().type.is_bool_type():
            atom = atom_template(inner)
            key = ("s" if atom[0] in static else "d") + ("n" if negated else "p")
            parts[key].append(atom)
        elif inner.is_equals():
            if not all(a.is_parameter_exp() or a.is_object_exp() for a in inner.args):
                raise PlanningError(unsupported_condition(inner, "numeric equality"))
            parts["ne" if negated else "eq"].append((_term(inner.arg(0)), _term(inner.arg(1))))
        elif inner.is_bool_constant():
            if inner.bool_constant_value() == negated:
                parts["never"].append(True)
        else:
            parts["complex"].append(cond)  # or / imply / forall / exists: grounded to CNF
    return parts


def _split_effects(action: InstantaneousAction) -> tuple[list, list, list]:
    add: list[AtomTemplate] = []
    delete: list[AtomTemplate] = []
    conditional: list[CondEffect] = []
    for eff in action.effects:
        if eff.is_conditional() or eff.is_forall():
            conditional.append(compile_effect(action.name, eff))
            continue
        if eff.is_increase() or eff.is_decrease():
            raise PlanningError(f"action {action.name}: numeric effect {eff} is not supported "
                                "(numeric fluents are read as costs and probabilities only)")
        if not eff.is_assignment():
            raise PlanningError(f"action {action.name}: unsupported effect {eff}")
        if not eff.fluent.fluent().type.is_bool_type():
            raise PlanningError(f"action {action.name}: numeric effect {eff} is not supported")
        if not eff.value.is_bool_constant():
            raise PlanningError(f"action {action.name}: non-constant effect {eff}")
        (add if eff.value.bool_constant_value() else delete).append(atom_template(eff.fluent))
    return add, delete, conditional


def axioms_of(problem: object) -> tuple:
    """The problem's derived predicates' rules (`pddl.lite.Axiom`; a UP problem has none)."""
    return tuple(getattr(problem, "axioms", ()))


def derived_names(problem: object) -> frozenset[str]:
    """The predicates the problem's rules define."""
    return frozenset(axiom.name for axiom in axioms_of(problem))


def is_instantaneous(action: Action | lite.InstantaneousAction) -> bool:
    """Whether the action is instantaneous (`lite` has no other kind; a UP action means UP
    is loaded already)."""
    if isinstance(action, lite.InstantaneousAction):
        return True
    from unified_planning.model import InstantaneousAction

    return isinstance(action, InstantaneousAction)


def _cost_exprs(problem: Problem) -> tuple[dict[str, FNode], FNode | None]:
    for metric in problem.quality_metrics:
        if metric.is_minimize_action_costs():
            # `get_action_cost` hashes the action (a walk over all its conditions and
            # effects); the metric normally holds the problem's own action objects.
            own = {id(a): c for a, c in metric.costs.items()}
            costs = {a.name: own[id(a)] if id(a) in own else metric.get_action_cost(a)
                     for a in problem.actions}
            return costs, metric.default
    return {}, None


def compile_schemas(
    pproblem: ProbabilisticProblem, static_names: frozenset[str] | None = None
) -> tuple[LiftedSchema, ...]:
    """Compile every action of the problem; raises PlanningError naming what is unsupported.
    `static_names`: the problem's static fluents, if the caller already knows them."""
    problem = pproblem.model
    static = (static_names if static_names is not None
              else {f.name for f in problem.get_static_fluents()})
    costs, _default = _cost_exprs(problem)  # default is 0 when a metric is given
    has_metric = bool(costs)
    schemas = []
    for action in problem.actions:
        try:
            schemas.append(_compile(pproblem, action, static, costs, has_metric))
        except PlanningError as exc:  # name the action, so the reader can place it
            raise in_action(action.name, exc) from None
    return tuple(schemas)


def _compile(pproblem: ProbabilisticProblem, action: Action, static: set[str] | frozenset[str],
             costs: dict[str, FNode], has_metric: bool) -> LiftedSchema:
    """One action as a `LiftedSchema`; raises PlanningError on what is unsupported."""
    if not is_instantaneous(action):
        raise PlanningError(f"action {action.name}: only instantaneous actions are supported")
    parts = _split_preconditions(action, static)
    add, delete, conditional = _split_effects(action)
    cost = compile_vector(costs.get(action.name), f"cost of {action.name}",
                          0.0 if has_metric else 1.0)
    prob = compile_vector(pproblem.success.get(action.name),
                          f"success probability of {action.name}", 1.0)
    return LiftedSchema(
        name=action.name,
        params=tuple("?" + p.name for p in action.parameters),
        param_types=tuple(p.type for p in action.parameters),
        static_pos=tuple(parts["sp"]), static_neg=tuple(parts["sn"]),
        pre_pos=tuple(parts["dp"]), pre_neg=tuple(parts["dn"]),
        equal=tuple(parts["eq"]), not_equal=tuple(parts["ne"]),
        add=tuple(add), delete=tuple(delete),
        cost=cost, probability=prob, never=bool(parts["never"]),
        complex=tuple(parts["complex"]), conditional=tuple(conditional),
    )
