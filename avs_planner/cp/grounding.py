"""Grounding a probabilistic task to bitsets, with a cache reused across replans.

Two stages. The *structure* (every ground action consistent with types and static atoms, and
the fact table) depends only on the domain, the objects and the static atoms, so it is cached
under that key. The *instance* (initial bitset, relaxed-reachable actions, costs and success
probabilities evaluated from numeric values) is rebuilt for every call and is cheap.
"""

from __future__ import annotations

import itertools
from collections import OrderedDict, defaultdict
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

from unified_planning.model import FNode, Problem

from avs_planner.cp.formulas import FormulaGrounder
from avs_planner.cp.schema import AtomTemplate, LiftedSchema, compile_schemas
from avs_planner.cp.task import Atom, GroundAction, GroundTask, WorldState
from avs_planner.errors import PlanningError
from avs_planner.pddl.model import ProbabilisticProblem

MAX_GROUND_ACTIONS = 2_000_000


@dataclass(frozen=True)
class _Proto:
    """A ground action before costs and probabilities are filled in."""

    schema: LiftedSchema
    binding: Mapping[str, str]
    action: GroundAction


@dataclass(frozen=True)
class GroundStructure:
    """The cached part of grounding: fact table and every statically possible ground action."""

    facts: tuple[Atom, ...]
    fact_index: Mapping[Atom, int]
    protos: tuple[_Proto, ...]
    static_atoms: frozenset[Atom]


def world_state(problem: Problem) -> WorldState:
    """The problem's initial state as atoms and numeric values (explicit :init entries)."""
    atoms: set[Atom] = set()
    values: dict[Atom, float] = {}
    for fluent_exp, value in problem.explicit_initial_values.items():
        key = (fluent_exp.fluent().name, *(str(a.object().name) for a in fluent_exp.args))
        if value.is_bool_constant():
            if value.bool_constant_value():
                atoms.add(key)
        elif value.is_int_constant() or value.is_real_constant():
            values[key] = float(value.constant_value())
    return WorldState(frozenset(atoms), values)


def _substitute(template: AtomTemplate, binding: Mapping[str, str]) -> Atom:
    # a binding maps every parameter; object names never start with "?", so get(t, t) is exact
    get = binding.get
    return (template[0], *map(get, template[1:], template[1:]))


class _StaticIndex:
    """Static true atoms, indexed by predicate and by (predicate, position, object)."""

    def __init__(self, atoms: frozenset[Atom]):
        self.by_pred: dict[str, list[tuple[str, ...]]] = defaultdict(list)
        self.by_pos: dict[tuple[str, int, str], list[tuple[str, ...]]] = defaultdict(list)
        for atom in sorted(atoms):
            args = atom[1:]
            self.by_pred[atom[0]].append(args)
            for i, obj in enumerate(args):
                self.by_pos[(atom[0], i, obj)].append(args)

    def candidates(self, template: AtomTemplate, binding: Mapping[str, str]):
        for i, term in enumerate(template[1:]):
            value = binding.get(term) if term[0] == "?" else term
            if value is not None:
                return self.by_pos.get((template[0], i, value), ())
        return self.by_pred.get(template[0], ())


def _match(template: AtomTemplate, args, binding: dict, domains) -> dict | None:
    terms = template[1:]
    if len(terms) != len(args):
        return None
    new = dict(binding)
    for term, value in zip(terms, args, strict=True):
        if term[0] != "?":
            if term != value:
                return None
        elif term in new:
            if new[term] != value:
                return None
        elif value in domains[term]:
            new[term] = value
        else:
            return None
    return new


def _join(atoms: Sequence[AtomTemplate], binding: dict, index: _StaticIndex, domains) -> Iterator:
    if not atoms:
        yield binding
        return
    first, rest = atoms[0], atoms[1:]
    for args in index.candidates(first, binding):
        extended = _match(first, args, binding, domains)
        if extended is not None:
            yield from _join(rest, extended, index, domains)


def _bindings(schema: LiftedSchema, index: _StaticIndex, order, member, static):
    """Every parameter binding consistent with types, static atoms and (in)equalities."""
    for partial in _join(schema.static_pos, {}, index, member):
        free = [p for p in schema.params if p not in partial]
        for values in itertools.product(*(order[p] for p in free)):
            binding = {**partial, **dict(zip(free, values, strict=True))}
            if _consistent(schema, binding, static):
                yield binding


def _consistent(schema: LiftedSchema, binding: Mapping[str, str], static) -> bool:
    def value(term: str) -> str:
        return binding[term] if term[0] == "?" else term

    if any(value(a) != value(b) for a, b in schema.equal):
        return False
    if any(value(a) == value(b) for a, b in schema.not_equal):
        return False
    return not any(_substitute(t, binding) in static for t in schema.static_neg)


class _FactTable:
    def __init__(self) -> None:
        self.facts: list[Atom] = []
        self.index: dict[Atom, int] = {}

    def bits(self, atoms) -> tuple[int, tuple[int, ...]]:
        index, facts = self.index, self.facts
        ids = set()
        for atom in atoms:
            i = index.get(atom)
            if i is None:
                i = index[atom] = len(facts)
                facts.append(atom)
            ids.add(i)
        mask = 0
        for i in ids:
            mask |= 1 << i
        return mask, tuple(sorted(ids))


def build_structure(
    problem: Problem, schemas: Sequence[LiftedSchema], static: frozenset[Atom],
    assumptive: Mapping[str, bool],
) -> GroundStructure:
    """Ground every action over the objects, filtered by types and static atoms."""
    index = _StaticIndex(static)
    table = _FactTable()
    static_names = {f.name for f in problem.get_static_fluents()}
    formulas = FormulaGrounder(
        static, static_names, lambda t: list(dict.fromkeys(o.name for o in problem.objects(t)))
    )
    protos: list[_Proto] = []
    for schema in schemas:
        if schema.never:
            continue
        order = {
            p: list(dict.fromkeys(o.name for o in problem.objects(t)))
            for p, t in zip(schema.params, schema.param_types, strict=True)
        }
        member = {p: set(names) for p, names in order.items()}
        for binding in _bindings(schema, index, order, member, static):
            proto = _proto(schema, binding, table, len(protos), assumptive, formulas)
            if proto is not None:
                protos.append(proto)
            if len(protos) > MAX_GROUND_ACTIONS:
                raise PlanningError(f"grounding exceeds {MAX_GROUND_ACTIONS} actions")
    return GroundStructure(tuple(table.facts), dict(table.index), tuple(protos), static)


def _proto(schema, binding, table: _FactTable, i: int, assumptive, formulas) -> _Proto | None:
    pos_atoms = [_substitute(t, binding) for t in schema.pre_pos]
    neg_atoms = [_substitute(t, binding) for t in schema.pre_neg]
    clauses: list[tuple[int, int]] = []
    if schema.complex:
        cnf = [c for node in schema.complex for c in formulas.cnf(node, binding)]
        for clause in sorted(cnf, key=lambda c: sorted(c)):
            if not clause:
                return None
            if len(clause) == 1:
                ((atom, positive),) = clause
                (pos_atoms if positive else neg_atoms).append(atom)
            else:
                pos, _ = table.bits(a for a, positive in sorted(clause) if positive)
                neg, _ = table.bits(a for a, positive in sorted(clause) if not positive)
                clauses.append((pos, neg))
    pre, pre_ids = table.bits(pos_atoms)
    neg, _ = table.bits(neg_atoms)
    if pre & neg:
        return None
    add, add_ids = table.bits(_substitute(t, binding) for t in schema.add)
    delete, _ = table.bits(_substitute(t, binding) for t in schema.delete)
    args = tuple(binding[p] for p in schema.params)
    action = GroundAction(
        index=i, name=schema.name, args=args, pre=pre, pre_neg=neg, add=add,
        delete=delete & ~add, cost=0.0, probability=1.0,
        assumptive=assumptive[schema.name], pre_facts=pre_ids, add_facts=add_ids,
        clauses=tuple(clauses),
    )
    return _Proto(schema, binding, action)


def _goal(problem: Problem, structure: GroundStructure) -> tuple[int, int, bool]:
    """Goal bitsets (positive, negative) and whether a static goal atom makes it impossible."""
    pos = neg = 0
    impossible = False
    index = structure.fact_index
    for goal in problem.goals:
        for cond in _flatten(goal):
            negated = cond.is_not()
            inner = cond.arg(0) if negated else cond
            if not inner.is_fluent_exp():
                raise PlanningError(f"unsupported goal condition {cond}")
            atom = (inner.fluent().name, *(a.object().name for a in inner.args))
            i = index.get(atom)
            if i is None:
                # never mentioned by any action: its truth is fixed by the initial state
                impossible |= (atom in structure.static_atoms) == negated
                continue
            if negated:
                neg |= 1 << i
            else:
                pos |= 1 << i
    return pos, neg, impossible or bool(pos & neg)


def _flatten(node: FNode) -> list[FNode]:
    if node.is_and():
        return [c for a in node.args for c in _flatten(a)]
    return [node]


def _reachable(protos: Sequence[_Proto], init: int) -> list[_Proto]:
    """Relaxed reachability (negative preconditions ignored): actions that may ever apply."""
    reached = init
    pending = list(protos)
    kept: list[_Proto] = []
    changed = True
    while changed:
        changed = False
        waiting = []
        for proto in pending:
            pre = proto.action.pre
            if pre & reached == pre:
                kept.append(proto)
                if proto.action.add & ~reached:
                    reached |= proto.action.add
                    changed = True
            else:
                waiting.append(proto)
        pending = waiting
    kept.sort(key=lambda p: p.action.index)
    return kept


def _relevant(protos: Sequence[_Proto], goal: int, goal_neg: int) -> list[_Proto]:
    """Backward relevance: keep actions that add a fact needed true or delete one needed
    false, where needs grow by the kept actions' conditions. Dropping the rest loses no plan
    (they can be cut from any plan, which only lowers its cost and raises its probability)."""
    need_true, need_false = goal, goal_neg
    kept = [False] * len(protos)
    changed = True
    while changed:
        changed = False
        for i, proto in enumerate(protos):
            a = proto.action
            if kept[i] or not (a.add & need_true or a.delete & need_false):
                continue
            kept[i] = changed = True
            need_true |= a.pre
            need_false |= a.pre_neg
            for pos, neg in a.clauses:
                need_true |= pos
                need_false |= neg
    return [p for p, keep in zip(protos, kept, strict=True) if keep]


def _probability(proto: _Proto, values: Mapping[Atom, float]) -> float:
    probability = proto.schema.probability(proto.binding, values)
    if not 0.0 <= probability <= 1.0:
        raise PlanningError(
            f"success probability of {proto.action.label} is {probability}, not in [0, 1]"
        )
    return probability


def _read_mask(protos: Sequence[_Proto], goal: int) -> int:
    """Every fact some action's precondition or the goal reads."""
    read = goal
    for proto in protos:
        read |= proto.action.reads
    return read


def _instantiate(
    proto: _Proto, index: int, probability: float, values: Mapping[Atom, float], read: int
) -> GroundAction:
    """The ground action with cost and probability; effects on facts nothing reads are
    dropped (e.g. `visited` of ordinary places), so states differing only there merge."""
    cost = proto.schema.cost(proto.binding, values)
    if cost < 0:
        raise PlanningError(f"cost of {proto.action.label} is negative ({cost})")
    a = proto.action
    add = a.add & read
    add_facts = a.add_facts if add == a.add else tuple(f for f in a.add_facts if read >> f & 1)
    return GroundAction(
        index, a.name, a.args, a.pre, a.pre_neg, add, a.delete & read, cost, probability,
        a.assumptive, a.pre_facts, add_facts, a.clauses,
    )


class GroundingCache:
    """Keeps compiled schemas and ground structures for the last few (domain, objects, statics)."""

    def __init__(self, size: int = 16):
        self.size = size
        self._schemas: OrderedDict[tuple, tuple[LiftedSchema, ...]] = OrderedDict()
        self._structures: OrderedDict[tuple, GroundStructure] = OrderedDict()
        self.hits = 0
        self.misses = 0

    def _remember(self, store: OrderedDict, key, make):
        if key in store:
            store.move_to_end(key)
            self.hits += 1
            return store[key]
        self.misses += 1
        value = store[key] = make()
        if len(store) > self.size:
            store.popitem(last=False)
        return value

    def schemas(self, pproblem: ProbabilisticProblem) -> tuple[LiftedSchema, ...]:
        key = self._schema_key(pproblem)
        return self._remember(self._schemas, key, lambda: compile_schemas(pproblem))

    @staticmethod
    def _schema_key(pproblem: ProbabilisticProblem) -> tuple:
        problem = pproblem.problem
        return (
            tuple(problem.actions),
            tuple(sorted((k, str(v)) for k, v in pproblem.success.items())),
            tuple(str(m) for m in problem.quality_metrics),
            frozenset(f.name for f in problem.get_static_fluents()),
        )

    def structure(self, pproblem: ProbabilisticProblem, state: WorldState) -> GroundStructure:
        problem = pproblem.problem
        schemas = self.schemas(pproblem)
        static_names = {f.name for f in problem.get_static_fluents()}
        static = frozenset(a for a in state.true_atoms if a[0] in static_names)
        objects = tuple((o.name, str(o.type)) for o in problem.all_objects)
        key = (self._schema_key(pproblem), objects, static)
        assumptive = {s.name: pproblem.is_assumptive(s.name) for s in schemas}
        return self._remember(
            self._structures, key,
            lambda: build_structure(problem, schemas, static, assumptive),
        )


DEFAULT_CACHE = GroundingCache()


def ground(
    pproblem: ProbabilisticProblem,
    state: WorldState | None = None,
    cache: GroundingCache | None = None,
) -> GroundTask:
    """Ground the task from `state` (default: the problem's :init) into a `GroundTask`."""
    cache = DEFAULT_CACHE if cache is None else cache
    state = world_state(pproblem.problem) if state is None else state
    structure = cache.structure(pproblem, state)
    init = 0
    for atom in state.true_atoms:
        i = structure.fact_index.get(atom)
        if i is not None:
            init |= 1 << i
    goal, goal_neg, impossible = _goal(pproblem.problem, structure)
    # drop actions that can never succeed (p = 0), then what only they made reachable;
    # only reachable actions are evaluated (others may read values :init does not give)
    possible, probability = [], {}
    for proto in _reachable(structure.protos, init):
        p = _probability(proto, state.values)
        if p > 0.0:
            possible.append(proto)
            probability[proto.action.index] = p
    reachable = _relevant(_reachable(possible, init), goal, goal_neg)
    read = _read_mask(reachable, goal | goal_neg)
    actions = [
        _instantiate(proto, i, probability[proto.action.index], state.values, read)
        for i, proto in enumerate(reachable)
    ]
    return GroundTask(
        facts=structure.facts, fact_index=structure.fact_index, actions=tuple(actions),
        init=init, goal=goal, goal_neg=goal_neg, goal_impossible=impossible,
        by_signature={(a.name.lower(), *(x.lower() for x in a.args)): a for a in actions},
    )
