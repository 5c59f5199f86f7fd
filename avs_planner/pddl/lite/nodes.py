"""Expression nodes (UP's `FNode` methods, printed as UP prints them) and the walks over them
that find fluents and free variables."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from avs_planner.pddl.lite.kinds import _CONSTANTS, _INFIX, _K, OperatorKind

if TYPE_CHECKING:
    from avs_planner.pddl.lite.declarations import Fluent, Object, Parameter, Type, Variable
    from avs_planner.pddl.lite.shared_environment import Environment


class FNode:
    """An expression node, shared per content (compare with `is`); UP's `FNode` methods."""

    __slots__ = ("node_type", "args", "_payload", "node_id", "type", "__weakref__")

    def __init__(self, kind: OperatorKind, args: tuple[FNode, ...], payload: Any, node_id: int,
                 type_: Type):
        self.node_type = kind
        self.args = args
        self._payload = payload
        self.node_id = node_id
        self.type = type_

    def __hash__(self) -> int:
        return self.node_id

    @property
    def environment(self) -> Environment:
        from avs_planner.pddl.lite.shared_environment import ENVIRONMENT  # it imports this

        return ENVIRONMENT

    def arg(self, index: int) -> FNode:
        return self.args[index]

    def is_constant(self) -> bool:
        return self.node_type in _CONSTANTS

    def constant_value(self) -> Any:
        assert self.is_constant()
        return self._payload

    def bool_constant_value(self) -> bool:
        assert self.node_type is _K.BOOL_CONSTANT
        return self._payload

    def fluent(self) -> Fluent:
        assert self.node_type is _K.FLUENT_EXP
        return self._payload

    def parameter(self) -> Parameter:
        assert self.node_type is _K.PARAM_EXP
        return self._payload

    def variable(self) -> Variable:
        assert self.node_type is _K.VARIABLE_EXP
        return self._payload

    def variables(self) -> list[Variable]:
        assert self.node_type in (_K.EXISTS, _K.FORALL)
        return list(self._payload)

    def object(self) -> Object:
        assert self.node_type is _K.OBJECT_EXP
        return self._payload

    def simplify(self) -> FNode:
        from avs_planner.pddl.lite.shared_environment import SIMPLIFIER  # it imports this

        return SIMPLIFIER.simplify(self)

    def is_bool_constant(self) -> bool:
        return self.node_type is _K.BOOL_CONSTANT

    def is_int_constant(self) -> bool:
        return self.node_type is _K.INT_CONSTANT

    def is_real_constant(self) -> bool:
        return self.node_type is _K.REAL_CONSTANT

    def is_true(self) -> bool:
        return self.node_type is _K.BOOL_CONSTANT and self._payload is True

    def is_false(self) -> bool:
        return self.node_type is _K.BOOL_CONSTANT and self._payload is False

    def is_and(self) -> bool:
        return self.node_type is _K.AND

    def is_or(self) -> bool:
        return self.node_type is _K.OR

    def is_not(self) -> bool:
        return self.node_type is _K.NOT

    def is_implies(self) -> bool:
        return self.node_type is _K.IMPLIES

    def is_exists(self) -> bool:
        return self.node_type is _K.EXISTS

    def is_forall(self) -> bool:
        return self.node_type is _K.FORALL

    def is_fluent_exp(self) -> bool:
        return self.node_type is _K.FLUENT_EXP

    def is_parameter_exp(self) -> bool:
        return self.node_type is _K.PARAM_EXP

    def is_variable_exp(self) -> bool:
        return self.node_type is _K.VARIABLE_EXP

    def is_object_exp(self) -> bool:
        return self.node_type is _K.OBJECT_EXP

    def is_plus(self) -> bool:
        return self.node_type is _K.PLUS

    def is_minus(self) -> bool:
        return self.node_type is _K.MINUS

    def is_times(self) -> bool:
        return self.node_type is _K.TIMES

    def is_div(self) -> bool:
        return self.node_type is _K.DIV

    def is_equals(self) -> bool:
        return self.node_type is _K.EQUALS

    def is_le(self) -> bool:
        return self.node_type is _K.LE

    def is_lt(self) -> bool:
        return self.node_type is _K.LT

    def __repr__(self) -> str:  # as UP prints it
        kind = self.node_type
        if kind is _K.BOOL_CONSTANT:
            return "true" if self._payload else "false"
        if kind is _K.INT_CONSTANT or kind is _K.REAL_CONSTANT:
            return str(self._payload)
        if kind is _K.FLUENT_EXP:
            return self._payload.name + _joined(", ", self.args)
        if kind in (_K.PARAM_EXP, _K.VARIABLE_EXP, _K.OBJECT_EXP):
            return self._payload.name
        if kind is _K.NOT:
            return f"(not {self.args[0]})"
        if kind is _K.EXISTS or kind is _K.FORALL:
            bound = ", ".join(str(v) for v in self._payload)
            return f"{'Exists' if kind is _K.EXISTS else 'Forall'} ({bound}) {self.args[0]}"
        return _joined(_INFIX[kind], self.args)


def _joined(op: str, args: tuple[FNode, ...]) -> str:
    return f"({op.join(str(a) for a in args)})" if args else ""



def free_fluents(node: FNode) -> frozenset[FNode]:
    """The fluent expressions in `node` (UP's `FreeVarsExtractor.get`)."""
    found: set[FNode] = set()
    stack = [node]
    while stack:
        current = stack.pop()
        if current.node_type is _K.FLUENT_EXP:
            found.add(current)
        stack.extend(current.args)
    return frozenset(found)


def free_variables(node: FNode) -> frozenset[Variable]:
    """The variables of `node` no quantifier in it binds (UP's `FreeVarsOracle`)."""
    kind = node.node_type
    if kind is _K.VARIABLE_EXP:
        return frozenset((node.variable(),))
    if not node.args:
        return frozenset()
    inner = frozenset().union(*(free_variables(a) for a in node.args))
    if kind is _K.EXISTS or kind is _K.FORALL:
        return inner.difference(node.variables())
    return inner


class FreeVarsExtractor:
    def get(self, node: FNode) -> frozenset[FNode]:
        return free_fluents(node)
