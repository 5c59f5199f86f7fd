"""UP's simplifier, for what the reader simplifies."""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING

from avs_planner.pddl.lite.declarations import UserType
from avs_planner.pddl.lite.kinds import _CONSTANTS, _K, ModelError
from avs_planner.pddl.lite.nodes import FNode

if TYPE_CHECKING:
    from avs_planner.pddl.lite.expression_manager import ExpressionManager


class Simplifier:
    """UP's `Simplifier` (without a problem) for what the reader simplifies: `when`
    conditions (Boolean connectives, equality, atoms) and probability products (`*`)."""

    def __init__(self, manager: ExpressionManager):
        self.em = manager

    def simplify(self, node: FNode) -> FNode:
        return self._walk(node, {})

    def _walk(self, node: FNode, memo: dict[FNode, FNode]) -> FNode:
        done = memo.get(node)
        if done is not None:
            return done
        args = [self._walk(a, memo) for a in node.args]
        kind, em = node.node_type, self.em
        if kind is _K.AND or kind is _K.OR:
            out = self._junction(kind is _K.AND, args)
        elif kind is _K.NOT:
            out = self._not(args[0])
        elif kind is _K.IMPLIES:
            out = self._implies(*args)
        elif kind is _K.EQUALS:
            out = self._equals(*args)
        elif kind is _K.FLUENT_EXP:
            out = em.FluentExp(node.fluent(), tuple(args))
        elif kind is _K.TIMES:
            out = self._times(args)
        elif kind in _CONSTANTS or kind in (_K.PARAM_EXP, _K.VARIABLE_EXP):
            out = node
        else:
            raise ModelError(f"simplifying {kind.name.lower()} is not mirrored")
        memo[node] = out
        return out

    def _not(self, child: FNode) -> FNode:
        if child.is_bool_constant():
            return self.em.Bool(not child.bool_constant_value())
        if child.is_not():
            return child.args[0]
        return self.em.Not(child)

    def _junction(self, conjunction: bool, args: list[FNode]) -> FNode:
        em = self.em
        if len(args) == 2 and args[0] is args[1]:
            return args[0]
        unit, zero = (em.TRUE(), em.FALSE()) if conjunction else (em.FALSE(), em.TRUE())
        kept: dict[FNode, bool] = {}
        for arg in args:
            if arg is unit:
                continue
            if arg is zero:
                return zero
            same = arg.is_and() if conjunction else arg.is_or()
            for part in (arg.args if same else (arg,)):
                if self._not(part) in kept:  # its negation
                    return zero
                kept[part] = True
        if not kept:
            return unit
        if len(kept) == 1:
            return next(iter(kept))
        return em.And(kept.keys()) if conjunction else em.Or(kept.keys())

    def _implies(self, left: FNode, right: FNode) -> FNode:
        em = self.em
        if left.is_bool_constant():
            return right if left.bool_constant_value() else em.TRUE()
        if right.is_bool_constant():
            return em.TRUE() if right.bool_constant_value() else em.Not(left)
        if left is right:
            return em.TRUE()
        return em.Implies(left, right)

    def _equals(self, left: FNode, right: FNode) -> FNode:
        em = self.em
        if left.is_constant() and right.is_constant():
            return em.Bool(left.constant_value() == right.constant_value())
        if left is right:
            return em.TRUE()
        lt, rt = left.type, right.type
        if (isinstance(lt, UserType) and isinstance(rt, UserType)
                and not lt.is_compatible(rt) and not rt.is_compatible(lt)):
            return em.FALSE()
        return em.Equals(left, right)

    def _times(self, args: list[FNode]) -> FNode:
        em = self.em
        kept: list[FNode] = []
        product: int | Fraction = 1
        for arg in args:
            for part in (arg.args if arg.is_times() else (arg,)):
                if part.is_int_constant() or part.is_real_constant():
                    if part.constant_value() == 0:
                        return em.Int(0)
                    product *= part.constant_value()
                else:
                    kept.append(part)
        if product != 1:
            number = (em.Int(product) if isinstance(product, int)
                      else em.Real(Fraction(product)))
            return em.Times(*kept, number)
        return em.Int(1) if not kept else em.Times(kept)
