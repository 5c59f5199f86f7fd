"""An independent reference for derived predicates: PDDL 2.2 semantics evaluated naively on
the lifted model, for checking what the grounder and both search engines compute.

Nothing of `avs_planner.cp` is used: formulas are evaluated on sets of ground atoms by
walking the model's nodes with every binding of their variables; the strata are found by
iterating the stratification constraints to a fixpoint; each stratum's rules are applied to
every binding of their heads until nothing changes; an action's effects (conditional and
universal ones included) are computed in the state before it, deletes before adds.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Iterator, Mapping

from avs_planner.pddl.lite import FNode, Problem

Atom = tuple[str, ...]
Binding = Mapping[str, str]


class Semantics:
    """The naive meaning of one problem's rules, actions and goal."""

    def __init__(self, problem: Problem):
        self.problem = problem
        self.axioms = list(problem.axioms)
        self.derived = {a.name for a in self.axioms}
        self.strata = self._strata()

    # ---- formulas ---------------------------------------------------------------------

    def objects(self, type_: object) -> list[str]:
        return [o.name for o in self.problem.objects(type_)]

    def value(self, node: FNode, binding: Binding) -> str:
        kind = node.node_type.name
        if kind == "PARAM_EXP":
            return binding["p:" + node.parameter().name]
        if kind == "VARIABLE_EXP":
            return binding["v:" + node.variable().name]
        return node.object().name

    def atom(self, node: FNode, binding: Binding) -> Atom:
        return (node.fluent().name, *(self.value(a, binding) for a in node.args))

    def holds(self, node: FNode, atoms: set[Atom], binding: Binding) -> bool:
        kind = node.node_type.name
        if kind == "FLUENT_EXP":
            return self.atom(node, binding) in atoms
        if kind == "AND":
            return all(self.holds(a, atoms, binding) for a in node.args)
        if kind == "OR":
            return any(self.holds(a, atoms, binding) for a in node.args)
        if kind == "NOT":
            return not self.holds(node.arg(0), atoms, binding)
        if kind == "IMPLIES":
            return not self.holds(node.arg(0), atoms, binding) or self.holds(
                node.arg(1), atoms, binding)
        if kind in ("FORALL", "EXISTS"):
            inner = (self.holds(node.arg(0), atoms, b)
                     for b in self._bind(node.variables(), binding))
            return all(inner) if kind == "FORALL" else any(inner)
        if kind == "EQUALS":
            return self.value(node.arg(0), binding) == self.value(node.arg(1), binding)
        if kind == "BOOL_CONSTANT":
            return node.bool_constant_value()
        raise AssertionError(f"the reference does not evaluate {node}")

    def _bind(self, variables: Iterable[object], binding: Binding, prefix: str = "v:"
              ) -> Iterator[dict[str, str]]:
        variables = list(variables)
        domains = [self.objects(v.type) for v in variables]
        for values in itertools.product(*domains):
            inner = dict(binding)
            inner.update((prefix + v.name, x) for v, x in zip(variables, values, strict=True))
            yield inner

    # ---- derived predicates -----------------------------------------------------------

    def _strata(self) -> dict[str, int]:
        """The lowest strata meeting: positive q in p's body -> s(q) <= s(p), negative ->
        s(q) < s(p); AssertionError when that has no solution (a negation in a cycle)."""
        constraints = [(axiom.name, q, negative) for axiom in self.axioms
                       for q, negative in self._occurrences(axiom.body, False)]
        stratum = dict.fromkeys(self.derived, 0)
        for _ in range(len(self.derived) + 1):
            changed = False
            for p, q, negative in constraints:
                if stratum[p] < stratum[q] + negative:
                    stratum[p] = stratum[q] + negative
                    changed = True
            if not changed:
                return stratum
        raise AssertionError("the rules are not stratified")

    def _occurrences(self, node: FNode, negated: bool) -> Iterator[tuple[str, bool]]:
        kind = node.node_type.name
        if kind == "FLUENT_EXP" and node.fluent().name in self.derived:
            yield node.fluent().name, negated
        elif kind == "NOT":
            yield from self._occurrences(node.arg(0), not negated)
        elif kind == "IMPLIES":
            yield from self._occurrences(node.arg(0), not negated)
            yield from self._occurrences(node.arg(1), negated)
        else:
            for arg in node.args:
                yield from self._occurrences(arg, negated)

    def closure(self, atoms: Iterable[Atom]) -> set[Atom]:
        """The basic atoms of `atoms` with every derived atom the rules give them."""
        state = {a for a in atoms if a[0] not in self.derived}
        for level in sorted(set(self.strata.values())):
            rules = [a for a in self.axioms if self.strata[a.name] == level]
            changed = True
            while changed:
                changed = False
                for axiom in rules:
                    for binding in self._bind(axiom.parameters, {}, prefix="p:"):
                        head = (axiom.name, *(binding["p:" + p.name]
                                              for p in axiom.parameters))
                        if head not in state and self.holds(axiom.body, state, binding):
                            state.add(head)
                            changed = True
        return state

    # ---- plans ------------------------------------------------------------------------

    def initial(self) -> set[Atom]:
        atoms = set()
        for fluent, value in self.problem.explicit_initial_values.items():
            if value.is_bool_constant() and value.bool_constant_value():
                atoms.add(self.atom(fluent, {}))
        return self.closure(atoms)

    def apply(self, state: set[Atom], name: str, args: tuple[str, ...]) -> set[Atom]:
        """The state after action `name(args)`; AssertionError if it is not applicable."""
        action = self.problem.action(name)
        binding = {"p:" + p.name: x for p, x in zip(action.parameters, args, strict=True)}
        for condition in action.preconditions:
            assert self.holds(condition, state, binding), f"({name} {' '.join(args)}): " \
                f"{condition} does not hold"
        adds, deletes = set(), set()
        for effect in action.effects:
            if not effect.fluent.fluent().type.is_bool_type():
                continue  # numeric effects (action costs): not a state's atoms
            for inner in self._bind(effect.forall, binding):
                if self.holds(effect.condition, state, inner):
                    target = adds if effect.value.bool_constant_value() else deletes
                    target.add(self.atom(effect.fluent, inner))
        assert not self.derived_atoms(adds | deletes), "an action changed a derived atom"
        return self.closure((state - deletes) | adds)

    def derived_atoms(self, atoms: Iterable[Atom]) -> set[Atom]:
        return {a for a in atoms if a[0] in self.derived}

    def goal_holds(self, state: set[Atom]) -> bool:
        return all(self.holds(g, state, {}) for g in self.problem.goals)

    def check_plan(self, steps: Iterable[tuple[str, tuple[str, ...]]]) -> set[Atom]:
        """Run the plan from :init; AssertionError unless every step applies and the goal
        holds at the end. Returns the final state."""
        state = self.initial()
        for name, args in steps:
            state = self.apply(state, name, args)
        assert self.goal_holds(state), "the goal does not hold at the end of the plan"
        return state
