"""The expression manager: one node per content, typed and checked as UP's type checker does,
with UP's constructors and their shortcuts."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from fractions import Fraction
from typing import Any

from avs_planner.pddl.lite.declarations import (
    BOOL,
    INT,
    REAL,
    Fluent,
    Object,
    Parameter,
    Type,
    UserType,
    Variable,
    _numeric,
)
from avs_planner.pddl.lite.interning import WeakTable
from avs_planner.pddl.lite.kinds import (
    _ARITHMETIC,
    _BOOLEAN,
    _K,
    ModelError,
    OperatorKind,
)
from avs_planner.pddl.lite.nodes import FNode

_Content = tuple[OperatorKind, tuple[FNode, ...], Any]


class ExpressionManager:
    """Makes the nodes, one per content, each typed (and checked) as UP's type checker
    types it; the constructors UP's builder calls, with UP's shortcuts. A node stays in the
    table while something holds it (`interning`), so reading text after text in one process
    does not grow it."""

    def __init__(self) -> None:
        self._nodes: WeakTable[FNode] = WeakTable()
        self._next_id = 1  # never reused: a node made again after its first died hashes anew
        self._true = self._node(_K.BOOL_CONSTANT, (), True)
        self._false = self._node(_K.BOOL_CONSTANT, (), False)

    @property
    def table_size(self) -> int:
        """How many nodes the table holds (those something still references)."""
        return len(self._nodes)

    def _node(self, kind: OperatorKind, args: tuple[FNode, ...], payload: Any = None) -> FNode:
        content = (kind, args, payload)
        found = self._nodes.get(content)
        if found is not None:
            return found
        node = FNode(kind, args, payload, self._next_id, _type_of(kind, args, payload))
        self._next_id += 1
        return self._nodes.setdefault(content, node)  # one node per content, even if raced

    def auto_promote(self, *args: Any) -> list[FNode]:
        out = []
        for arg in _flattened(args):
            if isinstance(arg, FNode):
                out.append(arg)
            elif isinstance(arg, bool):
                out.append(self.Bool(arg))
            elif isinstance(arg, int):
                out.append(self.Int(arg))
            elif isinstance(arg, Fraction):
                out.append(self.Int(arg.numerator) if arg.denominator == 1 else self.Real(arg))
            elif isinstance(arg, Fluent):
                out.append(self.FluentExp(arg))
            elif isinstance(arg, Parameter):
                out.append(self.ParameterExp(arg))
            elif isinstance(arg, Variable):
                out.append(self.VariableExp(arg))
            elif isinstance(arg, Object):
                out.append(self.ObjectExp(arg))
            else:
                raise ModelError(f"cannot make an expression of {arg!r}")
        return out

    # the constructors, named as UP's expression manager names them
    def And(self, *args: Any) -> FNode:
        items = tuple(self.auto_promote(*args))
        if not items:
            return self._true
        return items[0] if len(items) == 1 else self._node(_K.AND, items)

    def Or(self, *args: Any) -> FNode:
        items = tuple(self.auto_promote(*args))
        if not items:
            return self._false
        return items[0] if len(items) == 1 else self._node(_K.OR, items)

    def Not(self, expression: Any) -> FNode:
        (node,) = self.auto_promote(expression)
        if node.node_type is _K.NOT:
            return node.args[0]
        return self._node(_K.NOT, (node,))

    def Implies(self, left: Any, right: Any) -> FNode:
        return self._node(_K.IMPLIES, tuple(self.auto_promote(left, right)))

    def Exists(self, expression: Any, *variables: Variable) -> FNode:
        return self._quantifier(_K.EXISTS, expression, variables)

    def Forall(self, expression: Any, *variables: Variable) -> FNode:
        return self._quantifier(_K.FORALL, expression, variables)

    def _quantifier(self, kind: OperatorKind, expression: Any,
                    variables: tuple[Variable, ...]) -> FNode:
        if not variables or not all(isinstance(v, Variable) for v in variables):
            raise ModelError("a quantifier needs variables")
        return self._node(kind, tuple(self.auto_promote(expression)), variables)

    def FluentExp(self, fluent: Fluent, params: Iterable[Any] = ()) -> FNode:
        args = tuple(self.auto_promote(params))
        if fluent.arity != len(args):
            raise ModelError(f"fluent {fluent.name} has arity {fluent.arity}, not {len(args)}")
        return self._node(_K.FLUENT_EXP, args, fluent)

    def ParameterExp(self, param: Parameter) -> FNode:
        return self._node(_K.PARAM_EXP, (), param)

    def VariableExp(self, var: Variable) -> FNode:
        return self._node(_K.VARIABLE_EXP, (), var)

    def ObjectExp(self, obj: Object) -> FNode:
        return self._node(_K.OBJECT_EXP, (), obj)

    def TRUE(self) -> FNode:
        return self._true

    def FALSE(self) -> FNode:
        return self._false

    def Bool(self, value: bool) -> FNode:
        return self._true if value else self._false

    def Int(self, value: int) -> FNode:
        if not isinstance(value, int) or isinstance(value, bool):
            raise ModelError(f"expecting int, got {type(value).__name__}")
        return self._node(_K.INT_CONSTANT, (), value)

    def Real(self, value: Fraction) -> FNode:
        if not isinstance(value, Fraction):
            raise ModelError(f"expecting Fraction, got {type(value).__name__}")
        return self._node(_K.REAL_CONSTANT, (), value)

    def Plus(self, *args: Any) -> FNode:
        items = tuple(self.auto_promote(*args))
        if not items:
            return self.Int(0)
        return items[0] if len(items) == 1 else self._node(_K.PLUS, items)

    def Minus(self, left: Any, right: Any) -> FNode:
        return self._node(_K.MINUS, tuple(self.auto_promote(left, right)))

    def Times(self, *args: Any) -> FNode:
        items = tuple(self.auto_promote(*args))
        if not items:
            return self.Int(1)
        return items[0] if len(items) == 1 else self._node(_K.TIMES, items)

    def Div(self, left: Any, right: Any) -> FNode:
        return self._node(_K.DIV, tuple(self.auto_promote(left, right)))

    def LE(self, left: Any, right: Any) -> FNode:
        return self._node(_K.LE, tuple(self.auto_promote(left, right)))

    def GE(self, left: Any, right: Any) -> FNode:
        left, right = self.auto_promote(left, right)
        return self._node(_K.LE, (right, left))

    def LT(self, left: Any, right: Any) -> FNode:
        return self._node(_K.LT, tuple(self.auto_promote(left, right)))

    def GT(self, left: Any, right: Any) -> FNode:
        left, right = self.auto_promote(left, right)
        return self._node(_K.LT, (right, left))

    def Equals(self, left: Any, right: Any) -> FNode:
        return self._node(_K.EQUALS, tuple(self.auto_promote(left, right)))


def _flattened(args: tuple[Any, ...]) -> Iterator[Any]:
    for arg in args:
        if isinstance(arg, Iterable) and not isinstance(arg, str):
            yield from arg
        else:
            yield arg



def _type_of(kind: OperatorKind, args: tuple[FNode, ...], payload: Any) -> Type:
    """The node's type as UP's type checker finds it; `ModelError` where UP's raises."""
    if kind in _BOOLEAN:
        if any(a.type is not BOOL for a in args):
            raise ModelError(f"{kind.name.lower()} of a non-Boolean expression")
        return BOOL
    if kind is _K.FLUENT_EXP:
        if len(args) != len(payload.signature) or not all(
                p.type.is_compatible(a.type) for p, a in zip(payload.signature, args,
                                                             strict=False)):
            raise ModelError(f"arguments of {payload.name} do not fit its signature")
        return payload.type
    if kind in (_K.PARAM_EXP, _K.VARIABLE_EXP, _K.OBJECT_EXP):
        return payload.type
    if kind is _K.BOOL_CONSTANT:
        return BOOL
    if kind is _K.INT_CONSTANT:
        return INT
    if kind is _K.REAL_CONSTANT:
        return REAL
    if kind in _ARITHMETIC:
        if not all(_numeric(a.type) for a in args):
            raise ModelError(f"{kind.name.lower()} of a non-numeric expression")
        if kind is _K.DIV and not any(_has_fluent(a) for a in args):
            # UP's type checker divides the bounds of constant operands (and fails on 0)
            raise ModelError("a division of constants")
        return REAL if kind is _K.DIV or any(a.type is REAL for a in args) else INT
    if kind is _K.LE or kind is _K.LT:
        if not all(_numeric(a.type) for a in args):
            raise ModelError("a comparison of non-numeric expressions")
        return BOOL
    if kind is _K.EQUALS:
        return _equals_type(args)
    raise ModelError(f"unknown node kind {kind}")


def _equals_type(args: tuple[FNode, ...]) -> Type:
    """UP's `walk_equals`: not on Booleans; user types must share an ancestor; a number
    only with numbers (and, as in UP, a user type with anything not a user type)."""
    first = args[0].type
    if first is BOOL:
        raise ModelError("equality of Boolean terms")
    for arg in args:
        other = arg.type
        if (isinstance(first, UserType) and other is not first
                and not first.is_compatible(other) and not other.is_compatible(first)):
            if isinstance(other, UserType) and not any(
                    a is b for a in first.ancestors for b in other.ancestors):
                raise ModelError("equality of unrelated types")
        elif _numeric(first) and not _numeric(other):
            raise ModelError("equality of a number with a non-number")
    return BOOL


def _has_fluent(node: FNode) -> bool:
    return node.node_type is _K.FLUENT_EXP or any(_has_fluent(a) for a in node.args)
