"""Ground atoms as integers, so the grounder can work on whole arrays of bindings at once.

Every fluent (boolean or numeric) gets a block of codes: the code of `(f o1 .. ok)` is
`base[f] + sum(stride_i * local_i(o_i))`, where `local_i` is the object's position among the
objects of the fluent's i-th parameter type. A lifted atom under an array of bindings is then
a few integer array operations, and numeric expressions (costs, success probabilities) are
evaluated for many ground actions in one go.
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Callable, Iterable, Mapping, Sequence
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.task import Atom
from avs_planner.errors import PlanningError

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import FNode, Problem, Type

Columns = Mapping[str, np.ndarray]  # parameter ("?x") -> object ids, one per binding
MAX_CODE = 2**62


_FEW = 48  # below this many atoms of a fluent, `encode_all` encodes them one by one


def objects_by_type(problem: Problem) -> dict[str, np.ndarray]:
    """Object ids (positions in `problem.all_objects`) of every type that has objects,
    subtypes included, in the problem's order: one pass over the objects and their types'
    ancestors, instead of a pass over all objects per type (`Problem.objects(type)`), which
    dominated small problems."""
    by_type: dict[Type, list[int]] = {}
    for i, obj in enumerate(problem.all_objects):
        by_type.setdefault(obj.type, []).append(i)
    members: dict[str, list[int]] = {}
    for type_, ids in by_type.items():
        ancestor: Type | None = type_
        while ancestor is not None:
            members.setdefault(str(ancestor), []).extend(ids)
            ancestor = ancestor.father  # type: ignore[attr-defined]
    return {k: np.sort(np.array(v, dtype=np.int64)) for k, v in members.items()}


class AtomSpace:
    """Object ids, per-type object lists and the integer code of every possible atom."""

    def __init__(self, problem: Problem):
        self.problem = problem
        self.names: list[str] = [o.name for o in problem.all_objects]
        self.object_id: dict[str, int] = {n: i for i, n in enumerate(self.names)}
        self._of_type: dict[str, np.ndarray] = objects_by_type(problem)
        self._local: dict[str, np.ndarray] = {}
        self._locals: dict[str, tuple[np.ndarray, ...]] = {}  # per fluent, per argument
        self._names_of: dict[str, list[str]] = {}
        self.base: dict[str, int] = {}
        self.strides: dict[str, tuple[int, ...]] = {}
        self.arg_types: dict[str, tuple[Type, ...]] = {}
        self._starts: list[int] = []
        self._fluents: list[str] = []
        total = 0
        for fluent in problem.fluents:
            types = tuple(p.type for p in fluent.signature)
            sizes = [len(self.objects_of(t)) for t in types]
            strides = [1] * len(sizes)
            for i in range(len(sizes) - 2, -1, -1):
                strides[i] = strides[i + 1] * max(sizes[i + 1], 1)
            self.base[fluent.name] = total
            self.strides[fluent.name] = tuple(strides)
            self.arg_types[fluent.name] = types
            self._locals[fluent.name] = tuple(self._local_of(t) for t in types)
            self._starts.append(total)
            self._fluents.append(fluent.name)
            total += max(math.prod(sizes), 1)
            if total >= MAX_CODE:
                raise PlanningError(
                    f"too many possible atoms to ground (fluent {fluent.name} over "
                    f"{' x '.join(map(str, sizes))} objects)"
                )
        self.size = total
        self._decoded: dict[int, Atom] = {}
        self._name_arrays: dict[str, np.ndarray] = {}

    def objects_of(self, type_: Type) -> np.ndarray:
        """Object ids of `type_` (subtypes included), in the problem's order."""
        key = str(type_)
        ids = self._of_type.get(key)
        if ids is None:
            ids = self._of_type[key] = np.zeros(0, dtype=np.int64)  # a type without objects
        return ids

    def names_of(self, type_: Type) -> list[str]:
        """Object names of `type_` (subtypes included), in the problem's order."""
        key = str(type_)
        names = self._names_of.get(key)
        if names is None:
            names = self._names_of[key] = [self.names[i] for i in self.objects_of(type_).tolist()]
        return names

    def _local_of(self, type_: Type) -> np.ndarray:
        """Each object's position among the objects of `type_`, -1 if not of that type."""
        key = str(type_)
        local = self._local.get(key)
        if local is None:
            ids = self.objects_of(type_)
            local = self._local[key] = np.full(len(self.names), -1, dtype=np.int64)
            local[ids] = np.arange(len(ids))
        return local

    def encode_product(self, fluent: str, name_sets: Sequence[Iterable[str]]) -> np.ndarray:
        """Codes of every atom of `fluent` whose i-th argument is in `name_sets[i]` (names
        not of the argument's type, or unknown, are left out)."""
        if fluent not in self.base:
            return np.zeros(0, dtype=np.int64)
        codes = np.full(1, self.base[fluent], dtype=np.int64)
        for names, stride, local in zip(name_sets, self.strides[fluent], self._locals[fluent],
                                        strict=True):
            ids = np.array([self.object_id[n] for n in names if n in self.object_id],
                           dtype=np.int64)
            part = local[ids]
            part = part[part >= 0] * stride
            codes = np.add.outer(codes, part).ravel()
        return codes

    def encode_rows(self, template: tuple[str, ...], columns: Columns, rows: int) -> np.ndarray:
        """Codes of a lifted atom `(f ?x obj ...)` under `rows` bindings."""
        name = template[0]
        const = self.base[name]
        code = None  # built in place from the first parameter's lookup: few numpy calls
        for term_, stride, local in zip(template[1:], self.strides[name], self._locals[name],
                                        strict=True):
            if term_[0] == "?":
                part = local[columns[term_]]
                if stride != 1:
                    part *= stride
                code = part if code is None else np.add(code, part, out=code)
            else:
                const += stride * int(local[self.object_id[term_]])
        if code is None:
            return np.full(rows, const, dtype=np.int64)
        if const:
            code += const
        return code

    def encode_all(self, atoms: Iterable[Atom]) -> np.ndarray:
        """Codes of the atoms `encode` gives one (unknown or mistyped ones are left out), on
        arrays per fluent (0.8 vs 1.75 ms for `encode` per atom on the 445 valued atoms of a
        20-place AVS problem)."""
        groups: dict[str, list[Atom]] = {}
        for atom in atoms:
            groups.setdefault(atom[0], []).append(atom)
        parts = []
        for name, group in groups.items():
            if name not in self.strides:
                continue
            if len(group) < _FEW:  # numpy's per-call cost outweighs a loop
                codes = [c for c in map(self.encode, group) if c is not None]
                parts.append(np.array(codes, dtype=np.int64))
                continue
            group = [a for a in group if len(a) == len(self.strides[name]) + 1]
            codes, valid = self.fluent_codes(name, group)
            parts.append(codes[valid])
        return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)

    def fluent_codes(self, fluent: str, atoms: Sequence[Atom]) -> tuple[np.ndarray, np.ndarray]:
        """(code, valid) per atom of `fluent`, all of its arity, on arrays: invalid where an
        object is unknown or not of its argument's type (as `encode` gives None)."""
        strides = self.strides.get(fluent, ())
        arity = len(strides)
        codes = np.full(len(atoms), self.base.get(fluent, 0), dtype=np.int64)
        valid = np.ones(len(atoms), dtype=bool)
        if arity and len(atoms):
            flat = [o for a in atoms for o in a[1:]]
            ids = np.fromiter(map(self.object_id.get, flat, itertools.repeat(-1)),
                              dtype=np.int64, count=len(flat)).reshape(len(atoms), arity)
            for i, (stride, local) in enumerate(zip(strides, self._locals[fluent],
                                                    strict=True)):
                part = np.where(ids[:, i] >= 0, local[ids[:, i]], -1)
                valid &= part >= 0
                codes += stride * part
        return codes, valid

    def encode(self, atom: Atom) -> int | None:
        """Code of a ground atom; None if its fluent or an object is unknown or mistyped."""
        base = self.base.get(atom[0])
        if base is None or len(atom) - 1 != len(self.strides[atom[0]]):
            return None
        code = base
        for obj, stride, local in zip(atom[1:], self.strides[atom[0]], self._locals[atom[0]],
                                      strict=True):
            gid = self.object_id.get(obj)
            if gid is None or local[gid] < 0:
                return None
            code += stride * int(local[gid])
        return code

    def decode_many(self, codes: np.ndarray) -> list[Atom]:
        """`decode` for an array of codes: sorted, each fluent's codes are one slice, split
        into argument columns on arrays and zipped into atoms (no per-code Python work but
        the memo, which keeps one tuple object per atom)."""
        codes = np.asarray(codes, dtype=np.int64)
        order = np.argsort(codes, kind="stable")
        ordered = codes[order]
        bounds = np.searchsorted(ordered, self._starts).tolist() + [len(codes)]
        atoms: list[Atom] = []
        for i, name in enumerate(self._fluents):
            lo, hi = bounds[i], bounds[i + 1]
            if lo == hi:
                continue
            rest = ordered[lo:hi] - self._starts[i]
            columns = []
            for stride, type_ in zip(self.strides[name], self.arg_types[name], strict=True):
                local, rest = np.divmod(rest, stride)
                columns.append(self._name_array(type_)[local].tolist())
            atoms.extend(zip(itertools.repeat(name, hi - lo), *columns, strict=True))
        decoded = self._decoded
        out: list[Atom] = [()] * len(codes)
        for j, code, atom in zip(order.tolist(), ordered.tolist(), atoms, strict=True):
            out[j] = decoded.setdefault(code, atom)
        return out

    def atoms(self, codes: list[int]) -> list[Atom]:
        """`decode_many` through the memo first: a replan asks for the atoms it asked for
        last time, and a dict lookup per code beats the array split."""
        get = self._decoded.get
        out = [get(c) for c in codes]
        missing = [k for k, atom in enumerate(out) if atom is None]
        if missing:
            for k, atom in zip(missing, self.decode_many([codes[k] for k in missing]),
                               strict=True):
                out[k] = atom
        return out  # type: ignore[return-value]

    def _name_array(self, type_: Type) -> np.ndarray:
        """Object names of `type_` as a numpy object array, for decoding on arrays."""
        key = str(type_)
        array = self._name_arrays.get(key)
        if array is None:
            array = self._name_arrays[key] = np.array(self.names_of(type_), dtype=object)
        return array

    def decode(self, code: int) -> Atom:
        atom = self._decoded.get(code)
        if atom is not None:
            return atom
        i = int(np.searchsorted(self._starts, code, side="right")) - 1
        name = self._fluents[i]
        rest = code - self._starts[i]
        names = []
        for stride, type_ in zip(self.strides[name], self.arg_types[name], strict=True):
            local, rest = divmod(rest, stride)
            names.append(self.names[int(self.objects_of(type_)[local])])
        atom = self._decoded[code] = (name, *names)
        return atom


class NumericValues:
    """A call's numeric values (atom -> number) looked up by atom code. Per fluent, on first
    use, the codes of its valued atoms are computed on arrays and sorted; a lookup is then a
    binary search per binding. (Decoding each binding's code back to an atom for a dict
    lookup cost a few milliseconds per cold call on office-scale AVS problems.)"""

    def __init__(self, space: AtomSpace, values: Mapping[Atom, float]):
        self.space = space
        self.values = values
        self._groups: dict[str, list[tuple[Atom, float]]] | None = None
        self._coded: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def lookup(self, fluent: str, codes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(value per code, whether the code has a value); values of misses are arbitrary."""
        known, numbers = self._coded.get(fluent) or self._encode(fluent)
        if not len(known):
            return np.zeros(len(codes)), np.zeros(len(codes), dtype=bool)
        at = np.searchsorted(known, codes)
        np.minimum(at, len(known) - 1, out=at)
        return numbers[at], known[at] == codes

    def _encode(self, fluent: str) -> tuple[np.ndarray, np.ndarray]:
        """The sorted codes of the fluent's valued atoms (skipping unknown or mistyped
        objects, as `AtomSpace.encode` does) and their values in the same order."""
        if self._groups is None:
            groups: dict[str, list[tuple[Atom, float]]] = {}
            for atom, value in self.values.items():
                groups.setdefault(atom[0], []).append((atom, value))
            self._groups = groups
        arity = len(self.space.strides.get(fluent, ()))
        entries = [(a, v) for a, v in self._groups.get(fluent, ()) if len(a) == arity + 1]
        codes, valid = self.space.fluent_codes(fluent, [a for a, _ in entries])
        numbers = np.array([v for _, v in entries], dtype=float)
        codes, numbers = codes[valid], numbers[valid]
        order = np.argsort(codes, kind="stable")
        coded = self._coded[fluent] = (codes[order], numbers[order])
        return coded


VectorExpr = Callable[[AtomSpace, Columns, int, NumericValues], np.ndarray]
"""(space, columns, rows, numeric values) -> one value per row."""

_ARITH: dict[str, Callable[[float, float], float]] = {
    "PLUS": operator.add, "MINUS": operator.sub, "TIMES": operator.mul, "DIV": operator.truediv,
}


class ConstantExpr:
    """A `VectorExpr` that reads nothing; callers may use `value` without building columns."""

    __slots__ = ("value",)
    params: frozenset[str] = frozenset()

    def __init__(self, value: float):
        self.value = value

    def __call__(self, space, cols, rows, values) -> np.ndarray:
        return np.full(rows, self.value)


class _FluentExpr:
    """A numeric fluent term `(f ?x obj ...)`: its value per binding, an error naming the
    first atom without one. `params`: the parameters it reads (callers build only those
    columns)."""

    __slots__ = ("template", "where", "params")

    def __init__(self, template: tuple[str, ...], where: str):
        self.template = template
        self.where = where
        self.params = frozenset(t for t in template[1:] if t[0] == "?")

    def __call__(self, space, cols, rows, values) -> np.ndarray:
        return _lookup(space, self.template, cols, rows, values, self.where)


class _ArithExpr:
    """+ - * / over sub-expressions, left to right (division by zero gives inf or nan, which
    the grounder's checks then name)."""

    __slots__ = ("parts", "op", "params")

    def __init__(self, parts: list, op: Callable[[float, float], float]):
        self.parts = parts
        self.op = op
        self.params = frozenset().union(*(p.params for p in parts))

    def __call__(self, space, cols, rows, values) -> np.ndarray:
        acc = self.parts[0](space, cols, rows, values)
        for part in self.parts[1:]:
            with np.errstate(divide="ignore", invalid="ignore"):
                acc = self.op(acc, part(space, cols, rows, values))
        return acc


def compile_vector(node: FNode | None, where: str, default: float) -> VectorExpr:
    """A numeric expression (constants, fluent terms, + - * /) over arrays of bindings."""
    if node is None:
        return ConstantExpr(default)
    if node.is_constant():
        return ConstantExpr(float(Fraction(str(node.constant_value()))))
    if node.is_fluent_exp():
        return _FluentExpr((node.fluent().name, *(term(a) for a in node.args)), where)
    kind = node.node_type.name
    if kind in _ARITH and node.args:
        return _ArithExpr([compile_vector(a, where, default) for a in node.args], _ARITH[kind])
    raise PlanningError(f"{where}: unsupported numeric expression {node}")


def fluent_template(expr: VectorExpr) -> tuple[str, ...] | None:
    """The lifted atom `(f ?x obj ...)` of an expression that is one numeric fluent term."""
    return expr.template if isinstance(expr, _FluentExpr) else None


def term(node: FNode) -> str:
    """A lifted atom's argument: `?name` for a parameter, else the object's name."""
    if node.is_parameter_exp():
        return "?" + node.parameter().name
    if node.is_object_exp():
        return node.object().name
    raise PlanningError(f"unsupported argument {node} (only parameters and objects)")


def _lookup(space: AtomSpace, template, cols, rows, values: NumericValues, where
            ) -> np.ndarray:
    if rows == 0:
        return np.zeros(0)
    codes = space.encode_rows(template, cols, rows)
    out, found = values.lookup(template[0], codes)
    if not found.all():  # name the missing atom of the lowest code, as a sorted scan would
        atom = space.decode(int(codes[~found].min()))
        raise PlanningError(f"{where}: no value for ({' '.join(atom)}) in :init")
    return out
