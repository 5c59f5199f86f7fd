"""Conditional effects (`when`, `forall` in effects), compiled away while grounding.

Each ground action's conditional effects are instantiated (forall variables over their
type's objects); conditions on static atoms are decided at once (IPC maintenance's
`(forall (?plane) (when (at ?plane ?day ?airport) (done ?plane)))` becomes plain adds). What
is left depends on the state: the action is split into one copy per combination of its
remaining conditions, each copy requiring its combination to hold (the others to fail, as
disjunctive clauses) and carrying the matching effects. Copies keep the action's name and
arguments, so plans read as before; search and the delete-relaxation heuristics see
ordinary STRIPS rows with clauses, which they already support.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.errors import PlanningError

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import Effect, FNode, Type

AtomTemplate = tuple[str, ...]
Literal = tuple[int, bool]  # (atom code, positive)
MAX_CONDITIONS = 6  # dynamic conditions per ground action: 2^6 copies at most


@dataclass(frozen=True)
class CondEffect:
    """One effect `(forall (vars) (when (and literals) (add|delete atom)))`."""

    variables: tuple[tuple[str, Type], ...]
    pos: tuple[AtomTemplate, ...]
    neg: tuple[AtomTemplate, ...]
    atom: AtomTemplate
    adds: bool


def _term(node: FNode) -> str:
    if node.is_parameter_exp():
        return "?" + node.parameter().name
    if node.is_variable_exp():
        return "?" + node.variable().name
    if node.is_object_exp():
        return node.object().name
    raise PlanningError(f"unsupported argument {node} in a conditional effect")


def _template(node: FNode) -> AtomTemplate:
    return (node.fluent().name, *(_term(a) for a in node.args))


def compile_effect(action_name: str, eff: Effect) -> CondEffect:
    """A conditional or forall effect of a boolean fluent, with a conjunction of literals."""
    where = f"action {action_name}: conditional effect {eff}"
    if not eff.is_assignment() or not eff.fluent.fluent().type.is_bool_type():
        raise PlanningError(f"{where}: only boolean effects are supported")
    if not eff.value.is_bool_constant():
        raise PlanningError(f"{where}: non-constant effect")
    pos: list[AtomTemplate] = []
    neg: list[AtomTemplate] = []
    stack = [eff.condition]
    while stack:
        node = stack.pop()
        if node.is_and():
            stack.extend(node.args)
        elif node.is_bool_constant():
            if not node.bool_constant_value():
                neg.append(("=",))  # never holds: marked by an impossible literal
        elif node.is_not() and node.arg(0).is_fluent_exp():
            neg.append(_template(node.arg(0)))
        elif node.is_fluent_exp():
            pos.append(_template(node))
        else:
            raise PlanningError(f"{where}: only conjunctions of literals as conditions")
    variables = tuple(("?" + v.name, v.type) for v in eff.forall)
    return CondEffect(variables, tuple(pos), tuple(neg), _template(eff.fluent),
                      eff.value.bool_constant_value())


Encode = Callable[[tuple[str, ...]], int | None]


@dataclass
class Variant:
    """One copy of a ground action: extra conditions and effects (atom codes)."""

    pre: list[int]
    neg: list[int]
    clauses: list[tuple[tuple[int, ...], tuple[int, ...]]]
    add: list[int]
    delete: list[int]


def variants(
    effects: Sequence[CondEffect], binding: Mapping[str, str], encode: Encode,
    static: frozenset[tuple[str, ...]], static_names: frozenset[str],
    names_of: Callable[[Type], list[str]],
) -> list[Variant]:
    """The copies of one ground action (one copy, without extra conditions, when every
    condition is static)."""
    groups: dict[frozenset[Literal], tuple[list[int], list[int]]] = {}
    for effect in effects:
        for full in _bindings(effect, binding, names_of):
            condition = _condition(effect, full, encode, static, static_names)
            if condition is None:
                continue
            code = encode(_ground(effect.atom, full))
            if code is None:
                continue
            adds, deletes = groups.setdefault(condition, ([], []))
            (adds if effect.adds else deletes).append(code)
    base_add, base_delete = groups.pop(frozenset(), ([], []))
    conditions = list(groups)
    if len(conditions) > MAX_CONDITIONS:
        raise PlanningError(f"{len(conditions)} state-dependent effect conditions; at most "
                            f"{MAX_CONDITIONS} are supported (the ground action is split "
                            f"into a copy per combination, {2 ** MAX_CONDITIONS} at most)")
    out = []
    for chosen in itertools.product((True, False), repeat=len(conditions)):
        variant = Variant([], [], [], list(base_add), list(base_delete))
        for condition, holds in zip(conditions, chosen, strict=True):
            _require(variant, condition, holds)
            if holds:
                variant.add += groups[condition][0]
                variant.delete += groups[condition][1]
        out.append(variant)
    return out


def _require(variant: Variant, condition: frozenset[Literal], holds: bool) -> None:
    if holds:
        for code, positive in condition:
            (variant.pre if positive else variant.neg).append(code)
        return
    if len(condition) == 1:  # not (l): the negated literal
        ((code, positive),) = condition
        (variant.neg if positive else variant.pre).append(code)
        return
    # not (l1 and l2 ...): a clause true if a negative literal's atom holds or a positive's
    # does not
    variant.clauses.append((tuple(sorted(c for c, p in condition if not p)),
                            tuple(sorted(c for c, p in condition if p))))


def _bindings(effect: CondEffect, binding: Mapping[str, str],
              names_of: Callable[[Type], list[str]]) -> list[dict[str, str]]:
    if not effect.variables:
        return [dict(binding)]
    domains = [names_of(t) for _v, t in effect.variables]
    names = [v for v, _t in effect.variables]
    return [{**binding, **dict(zip(names, values, strict=True))}
            for values in itertools.product(*domains)]


def _ground(template: AtomTemplate, binding: Mapping[str, str]) -> tuple[str, ...]:
    return (template[0], *(binding.get(t, t) for t in template[1:]))


def _condition(effect: CondEffect, binding: Mapping[str, str], encode: Encode,
               static: frozenset[tuple[str, ...]], static_names: frozenset[str]
               ) -> frozenset[Literal] | None:
    """The condition's state-dependent literals, or None when it can never hold."""
    literals: set[Literal] = set()
    for templates, positive in ((effect.pos, True), (effect.neg, False)):
        for template in templates:
            if template == ("=",):
                return None
            atom = _ground(template, binding)
            if atom[0] in static_names:
                if (atom in static) != positive:
                    return None
                continue
            code = encode(atom)
            if code is None:  # a mistyped atom is never true
                if positive:
                    return None
                continue
            literals.add((code, positive))
    if any((code, not positive) in literals for code, positive in literals):
        return None
    return frozenset(literals)


def expand_rows(
    params: Sequence[str], columns: Mapping[str, np.ndarray], rows: int,
    space_names: Sequence[str], per_binding: Callable[[dict[str, str]], list[Variant]],
) -> tuple[np.ndarray, list[Variant]]:
    """Per ground action (row), its copies: the row index of each copy and the copies."""
    index: list[int] = []
    out: list[Variant] = []
    ids = np.stack([columns[p] for p in params], axis=1).tolist() if params else [[]] * rows
    for row, objects in enumerate(ids):
        binding = {p: space_names[i] for p, i in zip(params, objects, strict=True)}
        found = per_binding(binding)
        index += [row] * len(found)
        out += found
    return np.array(index, dtype=np.int64), out
