"""Grounding a probabilistic task to bitsets, with a cache reused across replans.

Two stages. The *structure* (every ground action consistent with types and static atoms, and
the fact table) depends only on the domain, the objects and the static atoms, so it is cached
under that key. The *instance* (initial bitset, relaxed-reachable actions, costs and success
probabilities evaluated from numeric values) is rebuilt for every call.

Both stages work on arrays: the structure (`structure.py`) holds the ground actions as rows of
fact ids, and the reachability and relevance fixpoints here run over those arrays. Only the
ground actions that survive are kept, as arrays; their `GroundAction` objects are built
when read (`action_table.py`).
"""

from __future__ import annotations

import gc
from collections import OrderedDict
from collections.abc import Iterator
from contextlib import contextmanager
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.action_table import ActionTable
from avs_planner.cp.compact import compact
from avs_planner.cp.derived import derived, ids_of, reachable, relevant, task_rows
from avs_planner.cp.encoding import ConstantExpr, NumericValues
from avs_planner.cp.goal import ground_goal, with_goal_rules
from avs_planner.cp.schema import (
    LiftedSchema,
    axioms_of,
    compile_schemas,
    derived_names,
    is_instantaneous,
)
from avs_planner.cp.settled import SettledAtoms, settled_atoms
from avs_planner.cp.structure import GroundStructure, bitset, build_structure
from avs_planner.cp.task import Atom, GroundTask, TaskArrays, WorldState
from avs_planner.cp.unsupported import UnsupportedError
from avs_planner.errors import PlanningError, SourcePosition
from avs_planner.pddl.diagnostics import Diagnostic, Severity
from avs_planner.pddl.model import ProbabilisticProblem

if TYPE_CHECKING:  # or the project's own model (`pddl.lite`), read through the same methods
    from unified_planning.model import FNode, Problem

    from avs_planner.cp.ground_axioms import GroundAxioms


def world_state(problem: Problem) -> WorldState:
    """The problem's initial state as atoms and numeric values (explicit :init entries)."""
    atoms: set[Atom] = set()
    values: dict[Atom, float] = {}
    # UP shares one node per object and per constant: each is read once, found again by its
    # id (hashing an FNode runs Python code; the nodes live as long as the problem)
    names: dict[int, str] = {}
    constants: dict[int, bool | float | None] = {}
    for fluent_exp, value in problem.explicit_initial_values.items():
        key = [fluent_exp.fluent().name]
        for arg in fluent_exp.args:
            name = names.get(id(arg))
            if name is None:
                name = names[id(arg)] = arg.object().name
            key.append(name)
        constant = constants.get(id(value), _UNREAD)
        if constant is _UNREAD:
            constant = constants[id(value)] = _constant(value)
        if constant is True:
            atoms.add(tuple(key))
        elif constant is not None and constant is not False:
            values[tuple(key)] = constant
    return WorldState(frozenset(atoms), values)


_UNREAD = object()


def _constant(value: FNode) -> bool | float | None:
    """True/False for a boolean constant, a float for a number, None for anything else."""
    if not value.is_constant():
        return None
    constant = value.constant_value()
    if isinstance(constant, bool):
        return constant
    if isinstance(constant, (int, Fraction)):
        return float(constant)
    return None


def static_fluent_names(problem: Problem) -> frozenset[str]:
    """Fluents no effect assigns and no rule derives: UP's `get_static_fluents`, without the
    walk over every expression UP also makes (for its unused fluents), which cost ~1 ms per
    cold call."""
    changed = set(derived_names(problem))
    for action in problem.actions:
        if not is_instantaneous(action) or action.simulated_effect is not None:
            return frozenset(f.name for f in problem.get_static_fluents())
        changed.update(e.fluent.fluent().name for e in action.effects)
    if problem.events or problem.processes or problem.timed_effects:
        return frozenset(f.name for f in problem.get_static_fluents())
    return frozenset(f.name for f in problem.fluents if f.name not in changed)


def _evaluate(st: GroundStructure, rows: np.ndarray, values: NumericValues,
              what: str) -> np.ndarray:
    """Success probability (`what` = "prob") or cost of the rows in the boolean mask. The
    last result per `what` is kept with the structure: a replan from a state with the same
    numeric values and the same rows (most replans) gets it without evaluating again."""
    memo = st.memo.setdefault("evaluated", {})
    key = rows.tobytes()
    hit = memo.get(what)
    if hit is not None and hit[1] == key and hit[0] == values.values:
        return hit[2]
    out = _evaluate_rows(st, rows, values, what)
    out.flags.writeable = False  # shared by the calls that hit
    memo[what] = (dict(values.values), key, out)
    return out


def _evaluate_rows(st: GroundStructure, rows: np.ndarray, values: NumericValues,
                   what: str) -> np.ndarray:
    out = np.zeros(st.size)
    for block in st.blocks:
        sel = rows[block.start:block.stop]
        if not sel.any():
            continue
        expr = block.schema.probability if what == "prob" else block.schema.cost
        if isinstance(expr, ConstantExpr):
            out[block.start:block.stop][sel] = expr.value
            continue
        columns, count = block.select(sel, getattr(expr, "params", None))
        out[block.start:block.stop][sel] = expr(st.space, columns, count, values)
    return out


def _check(st: GroundStructure, rows: np.ndarray, values: np.ndarray, what: str) -> None:
    if what == "prob":
        bad = rows & ~((values >= 0.0) & (values <= 1.0))
    else:
        bad = rows & ~((values >= 0.0) & np.isfinite(values))
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        if what == "prob":
            raise PlanningError(
                f"success probability of {st.label(row)} is {values[row]}, not in [0, 1]"
            )
        raise PlanningError(f"cost of {st.label(row)} is {values[row]} (must be >= 0)")


def _bits(flags: np.ndarray) -> int:
    return int.from_bytes(np.packbits(flags, bitorder="little").tobytes(), "little")


class _HashOnce:
    """A cache key whose (costly: UP actions hash structurally) hash is computed once."""

    __slots__ = ("value", "_hash")

    def __init__(self, value: tuple):
        self.value = value
        self._hash = hash(value)

    def __hash__(self) -> int:
        return self._hash

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _HashOnce) and (
            other is self or (other._hash == self._hash and other.value == self.value)
        )


def _rule_schemas(pproblem: ProbabilisticProblem, static_names: frozenset[str]
                  ) -> tuple[LiftedSchema, ...]:
    """The derived predicates' rule schemas (`axioms.py`, imported only for a problem with
    rules; so is `ground_axioms.py`)."""
    if not axioms_of(pproblem.model):
        return ()
    from avs_planner.cp.axioms import compile_axioms

    return compile_axioms(pproblem.model, static_names)


class GroundingCache:
    """Keeps compiled schemas and ground structures for the last few (domain, objects, statics)."""

    def __init__(self, size: int = 16):
        self.size = size
        self._schemas: OrderedDict[tuple, tuple[LiftedSchema, ...]] = OrderedDict()
        self._structures: OrderedDict[tuple, GroundStructure] = OrderedDict()
        self._problem_keys: OrderedDict[int, tuple] = OrderedDict()
        self._initial: OrderedDict[int, tuple[ProbabilisticProblem, WorldState]] = OrderedDict()
        self._settled_atoms: OrderedDict[int, tuple] = OrderedDict()
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
        """The actions' schemas, then the derived predicates' rule schemas (if any)."""
        key, names = self._keys(pproblem)
        return self._remember(self._schemas, key, lambda: compile_schemas(pproblem, names)
                              + _rule_schemas(pproblem, names))

    def _keys(self, pproblem: ProbabilisticProblem) -> tuple[tuple, frozenset[str]]:
        """The schema key and static fluent names of a problem, computed once per problem
        object (hashing UP actions and finding static fluents walks the whole domain). A
        problem must not be changed after it was grounded; build a new one instead."""
        known = self._problem_keys.get(id(pproblem))
        if known is not None and known[0] is pproblem:
            return known[1], known[2]
        problem = pproblem.model
        static_names = static_fluent_names(problem)
        key = _HashOnce((
            tuple(problem.actions),
            axioms_of(problem),
            tuple(sorted((k, str(v)) for k, v in pproblem.success.items())),
            tuple(str(m) for m in problem.quality_metrics),
            static_names,
        ))
        objects = _HashOnce(tuple((o.name, str(o.type)) for o in problem.all_objects))
        self._problem_keys[id(pproblem)] = (pproblem, key, static_names, objects)
        if len(self._problem_keys) > self.size:
            self._problem_keys.popitem(last=False)
        return key, static_names

    def initial_state(self, pproblem: ProbabilisticProblem) -> WorldState:
        """`world_state` of the problem's :init, kept for the last few problem objects (a
        problem is not changed once planned)."""
        hit = self._initial.get(id(pproblem))
        if hit is not None and hit[0] is pproblem:
            return hit[1]
        state = world_state(pproblem.model)
        self._initial[id(pproblem)] = (pproblem, state)  # a strong ref keeps the id unique
        while len(self._initial) > self.size:
            self._initial.popitem(last=False)
        return state

    def structure(self, pproblem: ProbabilisticProblem, state: WorldState) -> GroundStructure:
        problem = pproblem.model
        schema_key, static_names = self._keys(pproblem)
        schemas = self.schemas(pproblem)
        objects = self._problem_keys[id(pproblem)][3]
        static = frozenset(a for a in state.true_atoms if a[0] in static_names)
        settled = self._settled(pproblem, schemas, static_names)
        settled_key = settled.key(state)
        key = (schema_key, objects, static, settled_key)
        assumptive = {s.name: pproblem.is_assumptive(s.name) for s in schemas}
        return self._remember(
            self._structures, key,
            lambda: build_structure(problem, schemas, static, assumptive, static_names,
                                    settled, settled_key),
        )

    def _settled(self, pproblem: ProbabilisticProblem, schemas: tuple[LiftedSchema, ...],
                 static_names: frozenset[str]) -> SettledAtoms:
        """`settled.settled_atoms` of the problem, computed once per problem object."""
        hit = self._settled_atoms.get(id(pproblem))
        if hit is not None and hit[0] is pproblem and hit[1] is schemas:
            return hit[2]
        settled = settled_atoms(pproblem.model, schemas, static_names)
        self._settled_atoms[id(pproblem)] = (pproblem, schemas, settled)  # a strong ref
        while len(self._settled_atoms) > self.size:
            self._settled_atoms.popitem(last=False)
        return settled

    def forget_last_calls(self) -> None:
        """Drop what the last calls left for reuse (action tables, see `_action_table`, and
        evaluations, see `_evaluate`), so the next call grounds as a replan from a state
        with other actions and values would (benchmarks measure that case with it); the
        structures stay."""
        for structure in self._structures.values():
            structure.memo.pop("last_table", None)
            structure.memo.pop("evaluated", None)


DEFAULT_CACHE = GroundingCache()


@contextmanager
def gc_paused() -> Iterator[None]:
    """Planning allocates many small, acyclic objects; the cyclic collector's passes over a
    large heap then cost more than the grounding (measured 0.31 s vs 0.11 s for a 12-place
    AVS problem). It is paused for a planning call and restored after (as `timeit` does)."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def ground(
    pproblem: ProbabilisticProblem,
    state: WorldState | None = None,
    cache: GroundingCache | None = None,
) -> GroundTask:
    """Ground the task from `state` (default: the problem's :init) into a `GroundTask`.
    What it cannot take raises `UnsupportedError` at the action's or goal's position when
    the task was read from PDDL (the reader's own finding, if it made one)."""
    if pproblem.not_grounded:
        first = pproblem.not_grounded[0]
        raise UnsupportedError(first.message,
                               position=SourcePosition(first.file, first.line, first.column))
    with gc_paused():
        try:
            return _ground(pproblem, state, cache)
        except UnsupportedError as exc:
            raise exc.located(pproblem.sources) from None


def grounding_diagnostics(pproblem: ProbabilisticProblem) -> list[Diagnostic]:
    """What grounding the task from its :init refuses (what `avs plan` would stop at after
    the reader's checks, e.g. more state-dependent effect conditions than a ground action
    may have), as one error Diagnostic at the action's or goal's position, else []."""
    try:
        ground(pproblem, cache=GroundingCache(size=1))
    except UnsupportedError as exc:
        where = exc.position or SourcePosition(pproblem.problem_file, 1, 1)
        return [Diagnostic(where.file, where.line, where.column, Severity.ERROR,
                           "unsupported", exc.message)]
    except PlanningError as exc:  # a limit or a value of the problem, not one construct
        return [Diagnostic(pproblem.problem_file, 1, 1, Severity.ERROR, "grounding", str(exc))]
    return []


def _ground(
    pproblem: ProbabilisticProblem, state: WorldState | None, cache: GroundingCache | None
) -> GroundTask:
    cache = DEFAULT_CACHE if cache is None else cache
    state = cache.initial_state(pproblem) if state is None else state
    derived_predicates = derived_names(pproblem.model)
    if derived_predicates:  # the rules decide derived atoms; a state gives basic ones only
        state = WorldState(frozenset(a for a in state.true_atoms
                                     if a[0] not in derived_predicates), state.values)
    structure = cache.structure(pproblem, state)
    st = structure
    n = len(st.facts)
    init_ids = [i for i in map(st.fact_index.get, state.true_atoms) if i is not None]
    init = bitset(init_ids)
    goal = ground_goal(pproblem.model, st.fact_index, state.true_atoms)
    wanted, unwanted = goal.wanted
    reached = np.zeros(n + 2, dtype=bool)
    reached[init_ids] = True
    reached[n] = True  # the padding of preconditions
    # drop actions that can never succeed (p = 0), then what only they made reachable;
    # only reachable actions are evaluated (others may read values :init does not give)
    may_apply = reachable(st, reached, _not_blocked(st, reached))
    values = NumericValues(st.space, state.values)
    probability = _evaluate(st, may_apply, values, "prob")
    _check(st, may_apply, probability, "prob")
    possible = may_apply & (probability > 0.0)
    if (may_apply != possible).any():  # else reachability over `possible` is `may_apply`
        possible = reachable(st, reached, possible)
    rules = body = None
    if derived_predicates:  # rule rows (reached like actions) leave `possible` here
        rules, body = _split_rules(st, possible)
    if body is None:
        kept = relevant(st, possible, wanted, unwanted)
    else:  # every fact a rule reads is needed, either way (an over-approximation)
        needed = _bits(body[:n])
        kept = relevant(st, possible, wanted | needed, unwanted | needed)
    cost = _evaluate(st, kept, values, "cost")
    _check(st, kept, cost, "cost")
    # effects on facts nothing reads are dropped (e.g. `visited` of ordinary places), so
    # states differing only there merge
    read = np.zeros(n + 2, dtype=bool) if body is None else body
    read[ids_of(wanted | unwanted)] = True
    kept_rows = np.flatnonzero(kept)
    read[np.take(st.pre, kept_rows, axis=0).ravel()] = True  # np.take: faster than a mask
    read[np.take(st.pre_neg, kept_rows, axis=0).ravel()] = True
    d = derived(st)
    clauses = {}  # action index -> clauses as bitsets (few rows have any)
    if len(d.clause_rows):
        _, positives, negatives = d.clauses
        read[positives[kept[d.clause_pos_rows]]] = True
        read[negatives[kept[d.clause_neg_rows]]] = True
        with_clauses = d.clause_rows[kept[d.clause_rows]]
        clauses = dict(zip(np.searchsorted(kept_rows, with_clauses).tolist(),
                           map(d.clause_bits.__getitem__, with_clauses.tolist()), strict=True))
    read_mask = _bits(read[:n])
    cost, probability = np.take(cost, kept_rows), np.take(probability, kept_rows)
    actions, arrays, axioms = _action_table(st, kept_rows, cost, probability, read,
                                            read_mask, clauses, rules, derived_predicates)
    facts, fact_index = structure.facts, structure.fact_index
    if goal.rules:  # a goal that is not a conjunction of literals: one derived fact
        facts, fact_index, axioms = with_goal_rules(facts, fact_index, axioms, goal,
                                                    actions.memo)
    if axioms is not None:
        init = axioms.close(init)
    goal_pos, goal_neg = goal.task_goal
    return compact(GroundTask(
        facts=facts, fact_index=fact_index, actions=actions, init=init, goal=goal_pos,
        goal_neg=goal_neg, goal_impossible=goal.impossible, arrays=arrays, axioms=axioms,
    ))


def _split_rules(st: GroundStructure, possible: np.ndarray
                 ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The possible rows of derived predicates' rules (taken out of `possible`, in place)
    and every fact they read (bool over fact ids + pads), or (None, None) if there are no
    rule rows. Rule schemas come after the actions', so their rows are the last ones."""
    first = next((b.start for b in st.blocks if b.schema.is_rule), None)
    if first is None:
        return None, None
    rows = first + np.flatnonzero(possible[first:])
    possible[first:] = False
    n = len(st.facts)
    body = np.zeros(n + 2, dtype=bool)
    body[np.take(st.pre, rows, axis=0).ravel()] = True
    body[np.take(st.pre_neg, rows, axis=0).ravel()] = True
    for row in rows.tolist():
        for pos, neg in st.clauses.get(row, ()):
            body[list(pos)] = True
            body[list(neg)] = True
    body[n:] = False
    return rows, body


def _not_blocked(st: GroundStructure, true_now: np.ndarray) -> np.ndarray:
    """Rows that may ever apply as far as negative preconditions tell: not those that need
    false an atom true now that no action deletes (it stays true on every path). The delete
    relaxation ignores negative preconditions, so without this the heuristics count such
    actions: in an episode, an assumption that the target is in a room already searched
    (`(not (defined-exists ?l in ?r))` against a true, never deleted atom) made h_add promise
    a plan far likelier than any real one, and the search expanded every cheap move
    sequence first (1.3 million states for an 8-step plan on a 7-place problem)."""
    n = len(st.facts)
    deleted = np.zeros(n + 2, dtype=bool)
    deleted[st.delete.ravel()] = True
    settled = true_now.copy()
    settled[n:] = False  # the padding codes
    settled &= ~deleted
    if not settled.any() or st.pre_neg.shape[1] == 0:
        return np.ones(st.size, dtype=bool)
    return ~settled[st.pre_neg].any(axis=1)


def _action_table(st: GroundStructure, kept_rows: np.ndarray, cost: np.ndarray,
                  probability: np.ndarray, read: np.ndarray, read_mask: int,
                  clauses: dict, rules: np.ndarray | None = None,
                  derived: frozenset[str] = frozenset()
                  ) -> tuple[ActionTable, TaskArrays, GroundAxioms | None]:
    """The action table and arrays of these rows, costs and probabilities, and the ground
    rules of the `rules` rows: the previous call's on the same structure if they are the
    same (a replan whose new state reaches the same actions and rules), so what consumers
    keep with the table (the native packer's task, which holds the rules too) is reused;
    else new ones."""
    key = (kept_rows.tobytes(), cost.tobytes(), probability.tobytes(), read_mask,
           None if rules is None else rules.tobytes())
    last = st.memo.get("last_table")
    if last is not None and last[0] == key:
        return last[1], last[2], last[3]
    pre, pre_neg, add, delete = task_rows(st, kept_rows, read)
    arrays = TaskArrays(
        pre=pre, pre_neg=pre_neg, add=add, delete=delete,
        cost=cost, probability=probability, clauses=clauses,
        arg_ids=np.take(st.arg_ids, kept_rows, axis=0), objects=st.space.names,
    )
    actions = ActionTable(st, kept_rows, cost, probability, read_mask)
    axioms = None
    if rules is not None:
        from avs_planner.cp.ground_axioms import rules_of_rows

        axioms = rules_of_rows(st, rules, derived)
    st.memo["last_table"] = (key, actions, arrays, axioms)
    return actions, arrays, axioms
