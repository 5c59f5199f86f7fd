"""What a domain declares: types (and their manager), parameters, variables, objects and
fluents."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Iterator

from avs_planner.pddl.lite.interning import WeakTable
from avs_planner.pddl.lite.kinds import ModelError

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

    __slots__ = ("name", "father", "__weakref__")

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
    """The types; one user type per (name, father) while something holds it (`interning`)."""

    def __init__(self) -> None:
        self._user: WeakTable[UserType] = WeakTable()

    @property
    def table_size(self) -> int:
        """How many user types the table holds (those a live problem or node still uses)."""
        return len(self._user)

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
            found = self._user.setdefault(key, UserType(name, father))
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



def _numeric(t: Type) -> bool:
    return t.is_int_type() or t.is_real_type()
