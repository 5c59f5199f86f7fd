"""The task's goal: a conjunction of literals as goal bitsets, or any other formula as one
derived fact.

A goal that grounds to a conjunction of literals (literals, `and`, a `forall` over objects, a
negated `or`, an `exists` with one way to hold) is read as it always was: the atoms it needs
true and false, as bitsets over the grounding structure's facts, with no rule and no cost.

Any other goal (an `or`, an `exists`, an `imply`, an `and` or a `forall` under a `not`) is
compiled as Fast Downward compiles it: into a fresh derived predicate of arity 0
(`GOAL_NAME`: PDDL names cannot contain '@'; a fluent of that name in a problem built in
unified-planning moves it aside) whose rule's body is the goal formula. The task's goal is
that one atom; the closure of every state (`ground_axioms.py`: both search engines, the
monitor, `GroundTask.state_of`) holds it exactly where the goal holds, and the relaxed
heuristics reach it through the rules as they reach any derived fact.

Grounded, the body is put in negation normal form and its quantifiers are expanded over the
objects; atoms no action changes are decided from the state, as a literal goal's are (a
derived atom no rule derives is false). Each disjunction inside a conjunction gets an
auxiliary derived fact (`@goal.K`, with the values of the variables bound around it) and one
rule per disjunct (the Lloyd-Topor transformation), so the rules grow with the ground
formula, never with the product of its disjunctions as a DNF or a CNF would. Auxiliary facts
occur positively only; every goal rule is placed in one stratum above each derived fact the
goal reads, so a negated derived atom in the goal is read once its stratum is closed.
"""

from __future__ import annotations

import itertools
from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from avs_planner.cp.formulas import unsupported_condition
from avs_planner.cp.task import Atom
from avs_planner.cp.unsupported import UnsupportedError
from avs_planner.errors import PlanningError

if TYPE_CHECKING:  # UP's model, or the project's own (`pddl.lite`): the same methods
    from unified_planning.model import FNode, Problem

    from avs_planner.cp.ground_axioms import GroundAxioms

GOAL_NAME = "@goal"
MAX_GOAL_ATOMS = 2_000_000  # ground atoms the goal formula may expand to
Facts = frozenset[int]
Conj = tuple[Facts, Facts]  # facts true, facts false
Rule = tuple[int, tuple[int, ...], tuple[int, ...]]  # head, facts true, facts false
_NONE: Facts = frozenset()
_TRUE: Conj = (_NONE, _NONE)
Binding = dict[str, str]
Part = tuple["FNode", bool, Binding]  # (node, positive, binding)


@dataclass(frozen=True)
class GroundGoal:
    """The goal as bitsets over the structure's `n` facts, or as rules (`rules` not empty):
    new facts numbered from n (`facts`: the goal atom, then the auxiliary ones) and the
    rules deriving them; `reads` are the structure's facts the rules read, true and false
    (backward relevance and the grounder's read mask keep them)."""

    n: int
    pos: int = 0
    neg: int = 0
    impossible: bool = False
    facts: tuple[Atom, ...] = ()
    rules: tuple[Rule, ...] = ()
    reads: tuple[int, int] = (0, 0)

    @property
    def wanted(self) -> tuple[int, int]:
        """Structure facts a plan may need true, and false, to reach the goal."""
        return self.reads if self.rules else (self.pos, self.neg)

    @property
    def task_goal(self) -> tuple[int, int]:
        """The task's goal bitsets: the goal atom (fact n) when compiled to rules."""
        return (1 << self.n, 0) if self.rules else (self.pos, self.neg)


def ground_goal(problem: Problem, fact_index: Mapping[Atom, int],
                true_atoms: frozenset[Atom]) -> GroundGoal:
    """The problem's goal over a structure's facts (`fact_index`) from a state whose atoms
    outside the facts are `true_atoms` (no action changes those). Raises `UnsupportedError`
    naming the goal conjunct that cannot be grounded (a numeric comparison)."""
    n = len(fact_index)
    conds = [cond for goal in problem.goals for cond in flatten(goal)]
    literals: list[tuple[Atom, bool]] = []
    parts: list[Conj] = []
    choices: list[tuple[FNode, list[Conj]]] = []  # conjuncts with several ways to hold
    translator: _Translator | None = None
    impossible = False
    for k, cond in enumerate(conds):
        negated = cond.is_not()
        inner = cond.arg(0) if negated else cond
        if inner.is_fluent_exp() and all(a.is_object_exp() for a in inner.args):
            literals.append(((inner.fluent().name, *(a.object().name for a in inner.args)),
                             negated))
            continue
        if translator is None:
            translator = _Translator(problem, fact_index, true_atoms)
        try:
            ways = translator.disjuncts(cond, True, {})
        except PlanningError as exc:
            raise UnsupportedError(_goal_message(cond, str(exc)),
                                   goal_part=(k, len(conds))) from None
        if not ways:
            impossible = True
        elif len(ways) == 1:
            parts.append(ways[0])
        else:
            choices.append((cond, ways))
    if translator is None or not (translator.rules or choices):
        return _literal_goal(n, fact_index, true_atoms, literals, parts, impossible)
    if impossible:
        return GroundGoal(n, impossible=True)
    body = _conjunction(fact_index, true_atoms, literals, parts)
    if body is None:
        return GroundGoal(n, impossible=True)
    rules = translator.rules
    if len(choices) == 1 and body == _TRUE:  # the goal is one disjunction: a rule per way
        rules += [(n, tuple(sorted(p)), tuple(sorted(q))) for p, q in choices[0][1]]
    else:
        pos = set(body[0])
        for cond, ways in choices:
            pos.add(translator.choice(cond, True, {}, ways))
        rules.append((n, tuple(sorted(pos)), tuple(sorted(body[1]))))
    read_pos = read_neg = 0
    for _, pos_facts, neg_facts in rules:
        for f in pos_facts:
            if f < n:
                read_pos |= 1 << f
        for f in neg_facts:
            if f < n:
                read_neg |= 1 << f
    return GroundGoal(n, facts=tuple(translator.facts), rules=tuple(rules),
                      reads=(read_pos, read_neg))


def _literal_goal(n: int, index: Mapping[Atom, int], true_atoms: frozenset[Atom],
                  literals: list[tuple[Atom, bool]], parts: list[Conj],
                  impossible: bool) -> GroundGoal:
    """A goal that is a conjunction of literals, as bitsets (an atom no action touches has
    the truth of the initial state: one of the wrong truth makes the goal impossible)."""
    pos = neg = 0
    for atom, negated in literals:
        i = index.get(atom)
        if i is None:
            impossible |= (atom in true_atoms) == negated
            continue
        if negated:
            neg |= 1 << i
        else:
            pos |= 1 << i
    for true, false in parts:
        for i in true:
            pos |= 1 << i
        for i in false:
            neg |= 1 << i
    return GroundGoal(n, pos, neg, impossible or bool(pos & neg))


def _conjunction(index: Mapping[Atom, int], true_atoms: frozenset[Atom],
                 literals: list[tuple[Atom, bool]], parts: list[Conj]) -> Conj | None:
    """The literals and parts as one conjunction over fact ids, or None if it cannot hold."""
    pos: set[int] = set()
    neg: set[int] = set()
    for atom, negated in literals:
        i = index.get(atom)
        if i is None:
            if (atom in true_atoms) == negated:
                return None
            continue
        (neg if negated else pos).add(i)
    for true, false in parts:
        pos |= true
        neg |= false
    if not pos.isdisjoint(neg):
        return None
    return frozenset(pos), frozenset(neg)


class _Translator:
    """Grounds goal formulas to conjunctions over fact ids, adding an auxiliary derived
    fact (numbered after the structure's `n` facts and the goal atom) with one rule per
    disjunct for each disjunction met inside a conjunction (see the module docstring)."""

    def __init__(self, problem: Problem, index: Mapping[Atom, int],
                 true_atoms: frozenset[Atom]):
        self.problem = problem
        self.index = index
        self.true_atoms = true_atoms
        self.name = goal_name(problem)
        self.first = len(index)
        self.facts: list[Atom] = [(self.name,)]  # fact first + i
        self.rules: list[Rule] = []
        self._made: dict[tuple, int] = {}  # (node id, polarity, binding) -> auxiliary fact
        self._numbers: dict[tuple, int] = {}  # (node id, polarity, variables) -> K
        self._objects: dict[object, list[str]] = {}
        self._atoms = 0

    def disjuncts(self, node: FNode, positive: bool, binding: Binding) -> list[Conj]:
        """The ways `node` (negated unless `positive`) holds: conjunctions over fact ids,
        distinct; [] if it cannot hold, [(empty, empty)] if it always does."""
        found: dict[Conj, None] = {}
        if self._collect(node, positive, binding, found) or _tautology(found):
            return [_TRUE]
        return list(found)

    def _collect(self, node: FNode, positive: bool, binding: Binding,
                 found: dict[Conj, None]) -> bool:
        """Add the disjuncts of `node` to `found` (nested disjunctions flattened); True if
        one always holds."""
        while node.node_type.name == "NOT":
            node, positive = node.arg(0), not positive
        split = self._split(node, positive, binding)
        if split is not None and not split[0]:
            return any(self._collect(child, p, b, found) for child, p, b in split[1])
        way = self.conjunction(node, positive, binding)
        if way is None:
            return False
        if way == _TRUE:
            return True
        found[way] = None
        return False

    def conjunction(self, node: FNode, positive: bool, binding: Binding) -> Conj | None:
        """`node` (negated unless `positive`) as one conjunction over fact ids (a
        disjunction in it as its auxiliary fact); None if it cannot hold."""
        while node.node_type.name == "NOT":
            node, positive = node.arg(0), not positive
        split = self._split(node, positive, binding)
        if split is None:
            return self._leaf(node, positive, binding)
        conjunctive, parts = split
        if not conjunctive:
            made = self._made.get((id(node), positive, tuple(binding.items())))
            if made is not None:
                return frozenset((made,)), _NONE
            ways = self.disjuncts(node, positive, binding)
            if len(ways) <= 1:
                return ways[0] if ways else None
            return frozenset((self.choice(node, positive, binding, ways),)), _NONE
        pos: set[int] = set()
        neg: set[int] = set()
        for child, p, b in parts:
            way = self.conjunction(child, p, b)
            if way is None:
                return None
            pos |= way[0]
            neg |= way[1]
        if not pos.isdisjoint(neg):
            return None
        return frozenset(pos), frozenset(neg)

    def choice(self, node: FNode, positive: bool, binding: Binding,
               ways: Sequence[Conj]) -> int:
        """The auxiliary derived fact of `node` (negated unless `positive`) under `binding`,
        holding where one of its `ways` does: made once, with a rule per way. Its name is
        `@goal.K` and the values bound around it, K one number per node, polarity and bound
        variables (so a swap of two objects maps auxiliary facts onto each other)."""
        key = (id(node), positive, tuple(binding.items()))
        fact = self._made.get(key)
        if fact is None:
            number = self._numbers.setdefault((id(node), positive, tuple(binding)),
                                              len(self._numbers) + 1)
            fact = self._made[key] = self.first + len(self.facts)
            self.facts.append((f"{self.name}.{number}", *binding.values()))
            self.rules.extend((fact, tuple(sorted(p)), tuple(sorted(q))) for p, q in ways)
        return fact

    def _split(self, node: FNode, positive: bool, binding: Binding
               ) -> tuple[bool, Iterator[Part]] | None:
        """(whether it is a conjunction, its parts) of a junction or a quantifier (negated
        unless `positive`: the parts carry their own polarity); None for anything else."""
        kind = node.node_type.name
        if kind == "AND" or kind == "OR":
            return (kind == "AND") == positive, ((a, positive, binding) for a in node.args)
        if kind == "IMPLIES":  # (or (not A) B); negated: (and A (not B))
            return not positive, iter(((node.arg(0), not positive, binding),
                                       (node.arg(1), positive, binding)))
        if kind == "FORALL" or kind == "EXISTS":
            return (kind == "FORALL") == positive, self._bindings(node, positive, binding)
        return None

    def _bindings(self, node: FNode, positive: bool, binding: Binding) -> Iterator[Part]:
        variables = node.variables()
        keys = ["?v:" + v.name for v in variables]
        body = node.arg(0)
        for values in itertools.product(*(self._objects_of(v.type) for v in variables)):
            inner = dict(binding)
            inner.update(zip(keys, values, strict=True))
            yield body, positive, inner

    def _objects_of(self, type_: object) -> list[str]:
        names = self._objects.get(type_)
        if names is None:
            names = self._objects[type_] = [o.name for o in self.problem.objects(type_)]
        return names

    def _leaf(self, node: FNode, positive: bool, binding: Binding) -> Conj | None:
        kind = node.node_type.name
        if kind == "FLUENT_EXP":
            self._atoms += 1
            if self._atoms > MAX_GOAL_ATOMS:
                raise PlanningError(f"the goal grounds to more than {MAX_GOAL_ATOMS} atoms")
            atom = (node.fluent().name, *(_value(a, binding) for a in node.args))
            i = self.index.get(atom)
            if i is None:  # no action changes it: its truth is the state's
                return _TRUE if (atom in self.true_atoms) == positive else None
            fact = frozenset((i,))
            return (fact, _NONE) if positive else (_NONE, fact)
        if kind == "BOOL_CONSTANT":
            return _TRUE if node.bool_constant_value() == positive else None
        if kind == "EQUALS":
            if not all(a.node_type.name in _TERMS for a in node.args):
                raise PlanningError(unsupported_condition(node, "numeric equality"))
            same = _value(node.arg(0), binding) == _value(node.arg(1), binding)
            return _TRUE if same == positive else None
        what = "a numeric comparison" if kind in ("LT", "LE") else kind.lower()
        raise PlanningError(unsupported_condition(node, what))


_TERMS = ("PARAM_EXP", "VARIABLE_EXP", "OBJECT_EXP")


def _value(node: FNode, binding: Binding) -> str:
    kind = node.node_type.name
    if kind == "VARIABLE_EXP":
        return binding["?v:" + node.variable().name]
    if kind == "OBJECT_EXP":
        return node.object().name
    if kind == "PARAM_EXP":
        return binding["?" + node.parameter().name]
    raise PlanningError(f"unsupported argument {node}")


def _tautology(ways: Collection[Conj]) -> bool:
    """Whether two of the ways are one fact and its negation (one of them always holds)."""
    true = {next(iter(p)) for p, q in ways if len(p) == 1 and not q}
    return any(len(q) == 1 and not p and next(iter(q)) in true for p, q in ways)


def goal_name(problem: Problem) -> str:
    """`GOAL_NAME`, moved aside (primes added) if the problem has a fluent of that name or
    one of its auxiliary names (possible only for a problem built in unified-planning)."""
    name = GOAL_NAME
    fluents = [f.name for f in problem.fluents]
    while any(f == name or f.startswith(name + ".") for f in fluents):
        name += "'"
    return name


def with_goal_rules(facts: tuple[Atom, ...], fact_index: Mapping[Atom, int],
                    axioms: GroundAxioms | None, goal: GroundGoal, memo: dict | None
                    ) -> tuple[tuple[Atom, ...], Mapping[Atom, int], GroundAxioms]:
    """The task's facts (the structure's, then the goal's) and its rules (the domain's, then
    the goal's, in one stratum above every derived fact the goal reads). The last result is
    kept in `memo` (the action table's): a replan with the same goal rules gets the same
    objects, and with them what consumers keep (the native packer's task)."""
    hit = None if memo is None else memo.get("goal_rules")
    if (hit is not None and hit[0] is facts and hit[1] is axioms and hit[2] == goal.facts
            and hit[3] == goal.rules):
        return hit[4]
    from avs_planner.cp.ground_axioms import GroundAxioms, GroundRule

    strata = {} if axioms is None else {r.head: r.stratum for r in axioms.rules}
    level = 1 + max((strata.get(f, -1) for _, pos, neg in goal.rules for f in (*pos, *neg)),
                    default=-1)
    n = len(facts)
    new_ids = range(n, n + len(goal.facts))
    rules = [GroundRule(head, pos, neg, (), level) for head, pos, neg in goal.rules]
    merged = GroundAxioms([*(() if axioms is None else axioms.rules), *rules],
                          [*(() if axioms is None else axioms.derived), *new_ids])
    index = dict(fact_index)
    index.update(zip(goal.facts, new_ids, strict=True))
    result = (facts + goal.facts, index, merged)
    if memo is not None:
        memo["goal_rules"] = (facts, axioms, goal.facts, goal.rules, result)
    return result


def flatten(node: FNode) -> list[FNode]:
    """The conjuncts of a goal, nested `and`s flattened (as `SourceMap.goal_part` counts)."""
    if node.is_and():
        return [c for a in node.args for c in flatten(a)]
    return [node]


def _goal_message(cond: FNode, detail: str) -> str:
    """`detail` about the goal conjunct `cond`, without naming it twice."""
    own = f"unsupported condition {cond} "
    if detail.startswith(own):  # the conjunct itself is the construct refused
        return "unsupported goal condition " + detail.removeprefix("unsupported condition ")
    return f"unsupported goal condition {cond}: {detail}"
