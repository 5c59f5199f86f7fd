"""The project's own small task model: what `avs plan` grounds without unified-planning.

Importing unified-planning (UP) costs most of a short `avs plan` (its `Environment` imports
`unified_planning.engines`, which imports ConfigSpace and scipy.stats: ~0.8 s). The fast
reader (`up_builder`) builds a UP `Problem` through a few of UP's model calls; this module
offers those very calls (same names and arguments) on classes of its own, so the same builder
code fills either model, and the planner (`avs_planner.cp`) grounds either through the methods
they share (`FNode.is_and()`, `Effect.fluent`, `Problem.explicit_initial_values`, ...).

What is mirrored is what a PDDL read makes, as UP 1.3 does it: expressions shared per
content (so `is` compares them, as the builder relies on), `>`/`>=` as `<`/`<=` swapped, a
double `not` dropped, `and`/`or` of one argument being it; the type of every expression,
checked on creation as UP's type checker does; preconditions without duplicates, a `true` one
dropped; effects with only the `forall` variables they use, conflicting numeric effects
refused; names used twice refused (or allowed across kinds when the reader shares them); the
simplification of `when` conditions and of probability products; and how UP prints all of
it (error messages and cache keys print nodes, effects and metrics).

What it would have to mirror further (a simplification of quantifiers or numeric comparisons,
a division UP's type checker evaluates, a name clash UP would only warn about) raises
`ModelError` instead: the reader then reads the text with UP, as before, so a text this
model does not take reads exactly as it did. `tests/avs_planner/pddl/test_pddl_lite.py`
compares both models, printed and ground, on every file the project reads.
"""

from __future__ import annotations

import enum
from collections import OrderedDict
from collections.abc import Callable, Iterable, Iterator, Mapping
from fractions import Fraction
from typing import Any


class ModelError(Exception):
    """What UP's model refuses, or what this model does not mirror: read it with UP."""


class OperatorKind(enum.Enum):
    """The kinds of node this model makes, named as UP's `OperatorKind` members are."""

    AND = enum.auto()
    OR = enum.auto()
    NOT = enum.auto()
    IMPLIES = enum.auto()
    EXISTS = enum.auto()
    FORALL = enum.auto()
    FLUENT_EXP = enum.auto()
    PARAM_EXP = enum.auto()
    VARIABLE_EXP = enum.auto()
    OBJECT_EXP = enum.auto()
    BOOL_CONSTANT = enum.auto()
    INT_CONSTANT = enum.auto()
    REAL_CONSTANT = enum.auto()
    PLUS = enum.auto()
    MINUS = enum.auto()
    TIMES = enum.auto()
    DIV = enum.auto()
    LE = enum.auto()
    LT = enum.auto()
    EQUALS = enum.auto()


class EffectKind(enum.Enum):
    ASSIGN = enum.auto()
    INCREASE = enum.auto()
    DECREASE = enum.auto()


_K = OperatorKind
_BOOLEAN = frozenset((_K.AND, _K.OR, _K.NOT, _K.IMPLIES, _K.EXISTS, _K.FORALL))
_ARITHMETIC = frozenset((_K.PLUS, _K.MINUS, _K.TIMES, _K.DIV))
_CONSTANTS = frozenset((_K.BOOL_CONSTANT, _K.INT_CONSTANT, _K.REAL_CONSTANT, _K.OBJECT_EXP))
_INFIX = {_K.AND: " and ", _K.OR: " or ", _K.IMPLIES: " implies ", _K.PLUS: " + ",
          _K.MINUS: " - ", _K.TIMES: " * ", _K.DIV: " / ", _K.LE: " <= ", _K.LT: " < ",
          _K.EQUALS: " == "}


# ---- types ------------------------------------------------------------------------------

class Type:
    """A type as UP's: Boolean, integer, real (no bounds: PDDL's functions have none) or a
    user type with its father."""

    __slots__ = ()

    def is_bool_type(self) -> bool:
        return False

    def is_int_type(self) -> bool:
        return False

    def is_real_type(self) -> bool:
        return False

    def is_user_type(self) -> bool:
        return False

    def is_compatible(self, right: Type) -> bool:
        """Whether a value of type `right` may be given where `self` is expected."""
        if self is right:
            return True
        if isinstance(self, UserType) and isinstance(right, UserType):
            return any(t is self for t in right.ancestors)
        return self.is_real_type() and right.is_int_type()


class _BoolType(Type):
    __slots__ = ()

    def is_bool_type(self) -> bool:
        return True

    def __repr__(self) -> str:
        return "bool"


class _IntType(Type):
    __slots__ = ()

    def is_int_type(self) -> bool:
        return True

    def __repr__(self) -> str:
        return "integer"


class _RealType(Type):
    __slots__ = ()

    def is_real_type(self) -> bool:
        return True

    def __repr__(self) -> str:
        return "real"


BOOL, INT, REAL = _BoolType(), _IntType(), _RealType()


class UserType(Type):
    """A user type; one object per (name, father), as UP's type manager keeps them."""

    __slots__ = ("name", "father")

    def __init__(self, name: str, father: UserType | None = None):
        self.name = name
        self.father = father

    @property
    def ancestors(self) -> Iterator[UserType]:
        current: UserType | None = self
        while current is not None:
            yield current
            current = current.father

    def is_user_type(self) -> bool:
        return True

    def is_subtype(self, other: Type) -> bool:
        return any(t is other for t in self.ancestors)

    def __repr__(self) -> str:
        return self.name if self.father is None else f"{self.name} - {self.father.name}"


class TypeManager:
    def __init__(self) -> None:
        self._user: dict[tuple[str, UserType | None], UserType] = {}

    def BoolType(self) -> Type:
        return BOOL

    def IntType(self, lower: object = None, upper: object = None) -> Type:
        if lower is not None or upper is not None:
            raise ModelError("bounded integer types are not mirrored")
        return INT

    def RealType(self, lower: object = None, upper: object = None) -> Type:
        if lower is not None or upper is not None:
            raise ModelError("bounded real types are not mirrored")
        return REAL

    def UserType(self, name: str, father: Type | None = None) -> Type:
        if father is not None and not isinstance(father, UserType):
            raise ModelError("the father of a user type must be a user type")
        key = (name, father)
        found = self._user.get(key)
        if found is None:
            found = self._user[key] = UserType(name, father)
        return found


# ---- named things -----------------------------------------------------------------------

class _Typed:
    """A name with a type (a parameter, a variable or an object); equal by both, as UP's."""

    __slots__ = ("name", "type", "_hash")

    def __init__(self, name: str, type_: Type, environment: object = None):
        self.name = name
        self.type = type_
        self._hash = hash((type(self), name, id(type_)))

    def __eq__(self, other: object) -> bool:
        return (type(other) is type(self) and other.name == self.name  # type: ignore[attr-defined]
                and other.type is self.type)  # type: ignore[attr-defined]

    def __hash__(self) -> int:
        return self._hash

    def __repr__(self) -> str:
        return f"{self.type} {self.name}"


class Parameter(_Typed):
    __slots__ = ()


class Variable(_Typed):
    __slots__ = ()


class Object(_Typed):
    __slots__ = ()

    def __repr__(self) -> str:
        return self.name


class Fluent:
    """A predicate (Boolean) or function (real) with its signature."""

    __slots__ = ("name", "type", "signature", "_hash")

    def __init__(self, name: str, typename: Type | None = None,
                 _signature: OrderedDict[str, Type] | None = None, environment: object = None):
        self.name = name
        self.type = BOOL if typename is None else typename
        self.signature = [Parameter(n, t) for n, t in (_signature or {}).items()]
        for parameter in self.signature:
            if not parameter.type.is_user_type():
                raise ModelError(f"fluent {name}: parameters must have finite domains")
        self._hash = hash((name, id(self.type), tuple(self.signature)))

    @property
    def arity(self) -> int:
        return len(self.signature)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Fluent) and other.name == self.name
                and other.type is self.type and other.signature == self.signature)

    def __hash__(self) -> int:
        return self._hash

    def __repr__(self) -> str:
        sign = ""
        if self.signature:
            sign = "[" + ", ".join(f"{p.name}={p.type}" for p in self.signature) + "]"
        return f"{self.type} {self.name}{sign}"


# ---- expressions ------------------------------------------------------------------------

class FNode:
    """An expression node, shared per content (compare with `is`); UP's `FNode` methods."""

    __slots__ = ("node_type", "args", "_payload", "node_id", "type")

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


_Content = tuple[OperatorKind, tuple[FNode, ...], Any]


class ExpressionManager:
    """Makes the nodes, one per content, each typed (and checked) as UP's type checker
    types it; the constructors UP's builder calls, with UP's shortcuts."""

    def __init__(self) -> None:
        self._nodes: dict[_Content, FNode] = {}
        self._next_id = 1
        self._true = self._node(_K.BOOL_CONSTANT, (), True)
        self._false = self._node(_K.BOOL_CONSTANT, (), False)

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


def _numeric(t: Type) -> bool:
    return t.is_int_type() or t.is_real_type()


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


# ---- actions ----------------------------------------------------------------------------

class Effect:
    """One effect as UP's: the `forall` variables it uses, in the given order."""

    __slots__ = ("fluent", "value", "condition", "kind", "forall")

    def __init__(self, fluent: FNode, value: FNode, condition: FNode,
                 kind: EffectKind = EffectKind.ASSIGN, forall: Iterable[Variable] = ()):
        if free_fluents(fluent) - {fluent}:
            raise ModelError(f"the fluent {fluent} has fluents among its arguments")
        free = free_variables(fluent) | free_variables(value) | free_variables(condition)
        used: list[Variable] = []
        for variable in forall:
            if variable in free and variable not in used:
                used.append(variable)
        if free.difference(used):
            raise ModelError("unbound variables in an effect")
        self.fluent = fluent
        self.value = value
        self.condition = condition
        self.kind = kind
        self.forall = tuple(used)

    def is_forall(self) -> bool:
        return bool(self.forall)

    def is_conditional(self) -> bool:
        return not self.condition.is_true()

    def is_assignment(self) -> bool:
        return self.kind is EffectKind.ASSIGN

    def is_increase(self) -> bool:
        return self.kind is EffectKind.INCREASE

    def is_decrease(self) -> bool:
        return self.kind is EffectKind.DECREASE

    @property
    def environment(self) -> Environment:
        return ENVIRONMENT

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Effect) and other.fluent is self.fluent
                and other.value is self.value and other.condition is self.condition
                and other.kind is self.kind and set(other.forall) == set(self.forall))

    def __hash__(self) -> int:
        return (hash(self.fluent) + hash(self.value) + hash(self.condition) + hash(self.kind)
                + sum(map(hash, self.forall)))

    def __repr__(self) -> str:
        parts = []
        if self.forall:
            parts.append(f"forall {', '.join(str(v) for v in self.forall)}")
        if self.is_conditional():
            parts.append(f"if {self.condition} then")
        parts.append(str(self.fluent))
        parts.append({EffectKind.ASSIGN: ":=", EffectKind.INCREASE: "+=",
                      EffectKind.DECREASE: "-="}[self.kind])
        parts.append(str(self.value))
        return " ".join(parts)


class InstantaneousAction:
    """An action: parameters, preconditions and effects, added as UP's model adds them."""

    simulated_effect = None

    def __init__(self, _name: str, _parameters: OrderedDict[str, Type] | None = None,
                 _env: Environment | None = None):
        self.name = _name
        self._parameters = OrderedDict((n, Parameter(n, t)) for n, t in
                                       (_parameters or {}).items())
        self.preconditions: list[FNode] = []
        self.effects: list[Effect] = []
        self._assigned: dict[FNode, FNode] = {}
        self._changed: set[FNode] = set()

    @property
    def environment(self) -> Environment:
        return ENVIRONMENT

    @property
    def parameters(self) -> list[Parameter]:
        return list(self._parameters.values())

    def parameter(self, name: str) -> Parameter:
        return self._parameters[name]

    def is_conditional(self) -> bool:
        return any(e.is_conditional() for e in self.effects)

    def add_precondition(self, precondition: Any) -> None:
        (node,) = ENVIRONMENT.expression_manager.auto_promote(precondition)
        if node.type is not BOOL:
            raise ModelError("a precondition must be Boolean")
        if node.is_true():
            return
        if free_variables(node):
            raise ModelError(f"the precondition {node} has unbound variables")
        if node not in self.preconditions:
            self.preconditions.append(node)

    def add_effect(self, fluent: Any, value: Any, condition: Any = True,
                   forall: Iterable[Variable] = ()) -> None:
        self._add(EffectKind.ASSIGN, fluent, value, condition, forall)

    def add_increase_effect(self, fluent: Any, value: Any, condition: Any = True,
                            forall: Iterable[Variable] = ()) -> None:
        self._add(EffectKind.INCREASE, fluent, value, condition, forall)

    def add_decrease_effect(self, fluent: Any, value: Any, condition: Any = True,
                            forall: Iterable[Variable] = ()) -> None:
        self._add(EffectKind.DECREASE, fluent, value, condition, forall)

    def _add(self, kind: EffectKind, fluent: Any, value: Any, condition: Any,
             forall: Iterable[Variable]) -> None:
        fluent_exp, value_exp, condition_exp = ENVIRONMENT.expression_manager.auto_promote(
            fluent, value, condition)
        if not fluent_exp.is_fluent_exp():
            raise ModelError("an effect on something that is not a fluent")
        if condition_exp.type is not BOOL:
            raise ModelError("an effect condition must be Boolean")
        if not fluent_exp.type.is_compatible(value_exp.type):
            raise ModelError("an effect value of an incompatible type")
        if kind is not EffectKind.ASSIGN and not _numeric(fluent_exp.type):
            raise ModelError("increase or decrease of a non-numeric fluent")
        effect = Effect(fluent_exp, value_exp, condition_exp, kind, forall)
        self._check_conflicts(effect)
        self.effects.append(effect)

    def _check_conflicts(self, effect: Effect) -> None:
        """UP's `check_conflicting_effects` for an action: unconditional numeric effects on
        one fluent must agree (an assignment twice, or an assignment and a change)."""
        fluent = effect.fluent
        if effect.is_conditional() or fluent.type is BOOL:
            return
        if effect.is_assignment():
            if fluent in self._changed:
                raise ModelError(f"the effect {effect} conflicts with an increase/decrease")
            assigned = self._assigned.get(fluent)
            if assigned is None:
                self._assigned[fluent] = effect.value
            elif assigned is not effect.value and not (
                    assigned.is_constant() and effect.value.is_constant()
                    and assigned.constant_value() == effect.value.constant_value()):
                raise ModelError(f"the effect {effect} conflicts with another assignment")
            return
        if fluent in self._assigned:
            raise ModelError(f"the effect {effect} conflicts with an assignment")
        self._changed.add(fluent)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, InstantaneousAction) and other.name == self.name
                and other._parameters == self._parameters
                and set(other.preconditions) == set(self.preconditions)
                and set(other.effects) == set(self.effects))

    def __hash__(self) -> int:
        return (hash(self.name) + sum(map(hash, self._parameters.items()))
                + sum(map(hash, self.preconditions)) + sum(map(hash, self.effects)))

    def __repr__(self) -> str:
        lines = [f"action {self.name}"]
        if self._parameters:
            lines[0] += "(" + ", ".join(map(str, self.parameters)) + ")"
        lines[0] += " {"
        lines.append("    preconditions = [")
        lines += [f"      {c}" for c in self.preconditions]
        lines.append("    ]")
        lines.append("    effects = [")
        lines += [f"      {e}" for e in self.effects]
        lines.append("    ]")
        lines.append("  }")
        return "\n".join(lines)


# ---- metrics ----------------------------------------------------------------------------

class _Metric:
    @staticmethod
    def is_minimize_action_costs() -> bool:
        return False

    @property
    def environment(self) -> Environment:
        return ENVIRONMENT


class MinimizeActionCosts(_Metric):
    def __init__(self, costs: Mapping[InstantaneousAction, Any], default: Any = None,
                 environment: object = None):
        em = ENVIRONMENT.expression_manager
        self.costs: dict[InstantaneousAction, FNode] = {}
        for action, cost in costs.items():
            (node,) = em.auto_promote(cost)
            if not _numeric(node.type):
                raise ModelError("action costs must be numeric")
            self.costs[action] = node
        self.default: FNode | None = None
        if default is not None:
            (self.default,) = em.auto_promote(default)
            if not _numeric(self.default.type):
                raise ModelError("the default action cost must be numeric")

    @staticmethod
    def is_minimize_action_costs() -> bool:
        return True

    def get_action_cost(self, action: InstantaneousAction) -> FNode | None:
        return self.costs.get(action, self.default)

    def __repr__(self) -> str:
        costs: dict[str, FNode | None] = {a.name: c for a, c in self.costs.items()}
        costs["default"] = self.default
        return f"minimize actions-cost: {costs}"


class MinimizeMakespan(_Metric):
    def __repr__(self) -> str:
        return "minimize makespan"


class _ExpressionMetric(_Metric):
    _word = ""

    def __init__(self, expression: Any, environment: object = None):
        (self.expression,) = ENVIRONMENT.expression_manager.auto_promote(expression)
        if not _numeric(self.expression.type):
            raise ModelError("a metric expression must be numeric")

    def __repr__(self) -> str:
        return f"{self._word} {self.expression}"


class MinimizeExpressionOnFinalState(_ExpressionMetric):
    _word = "minimize"


class MaximizeExpressionOnFinalState(_ExpressionMetric):
    _word = "maximize"


# ---- the problem ------------------------------------------------------------------------

class Problem:
    """Types, fluents, objects, actions, initial values, goals and metrics, added through
    UP's calls with UP's checks; `to_up()` gives the UP problem of the same text (built when
    first asked, by the reader's recipe in `counterpart`)."""

    events: tuple = ()
    processes: tuple = ()
    timed_effects: Mapping = {}

    def __init__(self, name: str | None = None, environment: Environment | None = None, *,
                 initial_defaults: Mapping[Type, FNode] | None = None):
        self.name = name
        self._env = environment or ENVIRONMENT
        self._initial_defaults = dict(initial_defaults or {})
        self._user_types: list[UserType] = []
        self._fluents: dict[str, Fluent] = {}
        self._fluents_defaults: dict[Fluent, FNode] = {}
        self._actions: dict[str, InstantaneousAction] = {}
        self._objects: dict[str, Object] = {}
        self._type_names: dict[str, UserType] = {}
        self._initial_value: dict[FNode, FNode] = {}
        self._goals: list[FNode] = []
        self._metrics: list[_Metric] = []
        self.counterpart: Callable[[], tuple[Any, Mapping[str, Any]]] | None = None
        self._up: tuple[Any, Mapping[str, Any]] | None = None

    @property
    def environment(self) -> Environment:
        return self._env

    def to_up(self) -> tuple[Any, Mapping[str, Any]]:
        """The UP problem of the same text and its success expressions (UP nodes), built
        once, when first asked."""
        if self._up is None:
            if self.counterpart is None:
                raise ModelError(f"problem {self.name} has no unified-planning counterpart")
            self._up = self.counterpart()
        return self._up

    # ---- adding ---------------------------------------------------------------------

    def has_name(self, name: str) -> bool:
        return (name in self._actions or name in self._fluents or name in self._objects
                or name in self._type_names)

    def _check_name(self, name: str, same_kind: Mapping[str, object]) -> None:
        """UP's rule: a name used twice is an error, unless the environment lets kinds share
        names (then UP only warns, and the reader does not show that warning)."""
        if self.has_name(name) and (self._env.error_used_name or name in same_kind):
            raise ModelError(f"name {name} already defined")

    def _add_user_type(self, type_: Type) -> None:
        if not isinstance(type_, UserType):
            raise ModelError("not a user type")
        if any(t is type_ for t in self._user_types):
            return
        if self.has_name(type_.name):
            # UP refuses it, or warns in words the reader does not filter
            raise ModelError(f"the type name {type_.name} is already used")
        if type_.father is not None:
            self._add_user_type(type_.father)
        self._user_types.append(type_)
        self._type_names.setdefault(type_.name, type_)

    def add_fluent(self, fluent: Fluent, *, default_initial_value: Any = None) -> Fluent:
        self._check_name(fluent.name, self._fluents)
        self._fluents[fluent.name] = fluent
        if default_initial_value is not None:
            (self._fluents_defaults[fluent],) = self._env.expression_manager.auto_promote(
                default_initial_value)
        elif fluent.type in self._initial_defaults:
            self._fluents_defaults[fluent] = self._initial_defaults[fluent.type]
        if fluent.type.is_user_type():
            self._add_user_type(fluent.type)
        for parameter in fluent.signature:
            self._add_user_type(parameter.type)
        return fluent

    def add_object(self, obj: Object) -> Object:
        self._check_name(obj.name, self._objects)
        self._objects[obj.name] = obj
        self._add_user_type(obj.type)
        return obj

    def add_action(self, action: InstantaneousAction) -> None:
        self._check_name(action.name, self._actions)
        self._actions[action.name] = action
        for parameter in action.parameters:
            self._add_user_type(parameter.type)

    def set_initial_value(self, fluent: Any, value: Any) -> None:
        fluent_exp, value_exp = self._env.expression_manager.auto_promote(fluent, value)
        if not fluent_exp.is_fluent_exp():
            raise ModelError("an initial value for something that is not a fluent")
        if not fluent_exp.type.is_compatible(value_exp.type):
            raise ModelError("an initial value of an incompatible type")
        self._initial_value[fluent_exp] = value_exp

    def add_goal(self, goal: Any) -> None:
        (node,) = self._env.expression_manager.auto_promote(goal)
        if node.type is not BOOL:
            raise ModelError("a goal must be Boolean")
        if not node.is_true():
            self._goals.append(node)

    def add_quality_metric(self, metric: _Metric) -> None:
        self._metrics.append(metric)

    # ---- reading --------------------------------------------------------------------

    @property
    def user_types(self) -> list[UserType]:
        return self._user_types

    @property
    def fluents(self) -> list[Fluent]:
        return list(self._fluents.values())

    @property
    def fluents_defaults(self) -> dict[Fluent, FNode]:
        return self._fluents_defaults

    @property
    def actions(self) -> list[InstantaneousAction]:
        return list(self._actions.values())

    @property
    def all_objects(self) -> list[Object]:
        return list(self._objects.values())

    def objects(self, type_: Type) -> Iterator[Object]:
        """The objects of `type_` and of its subtypes."""
        for obj in self._objects.values():
            if obj.type.is_subtype(type_):  # type: ignore[attr-defined]
                yield obj

    @property
    def explicit_initial_values(self) -> dict[FNode, FNode]:
        return self._initial_value

    @property
    def goals(self) -> list[FNode]:
        return self._goals

    @property
    def quality_metrics(self) -> list[_Metric]:
        return self._metrics

    def has_fluent(self, name: str) -> bool:
        return name in self._fluents

    def fluent(self, name: str) -> Fluent:
        return self._fluents[name]

    def has_object(self, name: str) -> bool:
        return name in self._objects

    def object(self, name: str) -> Object:
        return self._objects[name]

    def has_action(self, name: str) -> bool:
        return name in self._actions

    def action(self, name: str) -> InstantaneousAction:
        return self._actions[name]

    def has_type(self, name: str) -> bool:
        return name in self._type_names

    def user_type(self, name: str) -> UserType:
        return self._type_names[name]

    def get_static_fluents(self) -> set[Fluent]:
        """Fluents no effect changes."""
        changed = {e.fluent.fluent().name for a in self._actions.values() for e in a.effects}
        return {f for f in self._fluents.values() if f.name not in changed}


# ---- the environment --------------------------------------------------------------------

class Environment:
    """The managers a read uses (shared by all reads, as UP's global environment is) and
    whether kinds may share names (UP's `error_used_name`, per read here)."""

    def __init__(self, error_used_name: bool = True,
                 shared_from: Environment | None = None):
        self.error_used_name = error_used_name
        if shared_from is None:
            self.expression_manager = ExpressionManager()
            self.type_manager = TypeManager()
            self.simplifier = Simplifier(self.expression_manager)
            self.free_vars_extractor = FreeVarsExtractor()
        else:
            self.expression_manager = shared_from.expression_manager
            self.type_manager = shared_from.type_manager
            self.simplifier = shared_from.simplifier
            self.free_vars_extractor = shared_from.free_vars_extractor


ENVIRONMENT = Environment()
SIMPLIFIER = ENVIRONMENT.simplifier


def environment(names_shared: bool) -> Environment:
    """The shared environment, with names shared across kinds or not."""
    if not names_shared:
        return ENVIRONMENT
    return Environment(error_used_name=False, shared_from=ENVIRONMENT)


def is_lite(model: object) -> bool:
    """Whether a planning model is this module's (else it is a UP problem)."""
    return isinstance(model, Problem)
