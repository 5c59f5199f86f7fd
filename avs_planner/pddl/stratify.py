"""Strata of derived predicates (PDDL 2.2 `:derived`): the order their rules are evaluated in.

A derived predicate p depends on each derived predicate q its rules' bodies name, positively
or (under a `not`, or in the antecedent of an `imply`) negatively; quantifiers, `and` and `or`
keep the polarity. The rules are stratified when no cycle of dependencies goes through a
negative one: then p's stratum is at least each positive q's and above each negative q's,
and evaluating the strata in order, each to its least fixpoint, gives the rules' meaning
(Thiébaux, Hoffmann and Nebel, "In Defense of PDDL Axioms", AIJ 2005).

This module only looks at names; the reader's check (`pddl/axioms.py`) places what it finds
in the text, the grounder (`cp/axioms.py`) orders the rules by it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

Dependency = tuple[str, bool]  # (derived predicate named in a body, negated there)


@dataclass(frozen=True)
class Violation:
    """`head`'s rules negate `body`, which depends on `head` again: `cycle` runs from `head`
    through `body` back to `head`."""

    head: str
    body: str
    cycle: tuple[str, ...]


def stratify(dependencies: Mapping[str, Iterable[Dependency]]
             ) -> tuple[dict[str, int], list[Violation]]:
    """The stratum (0, 1, ...) of every derived predicate (the keys; dependencies on other
    names are ignored), each as low as the rules allow, and every negative dependency inside
    a cycle (then the strata are not meaningful)."""
    edges = {p: sorted({(q, neg) for q, neg in deps if q in dependencies})
             for p, deps in dependencies.items()}
    component = _components(edges)
    violations = [Violation(p, q, _cycle(edges, component, p, q))
                  for p in edges for q, negated in edges[p]
                  if negated and component[q] == component[p]]
    stratum: dict[int, int] = {}
    for c in sorted(set(component.values())):  # components come dependencies first
        members = [p for p in edges if component[p] == c]
        stratum[c] = max((stratum[component[q]] + negated for p in members
                          for q, negated in edges[p] if component[q] != c), default=0)
    return {p: stratum[component[p]] for p in edges}, violations


def _components(edges: Mapping[str, list[Dependency]]) -> dict[str, int]:
    """Strongly connected components (Tarjan's, iterative), numbered so that a component
    comes after every component it depends on."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    component: dict[str, int] = {}
    counter = 0
    for root in edges:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            node, i = work.pop()
            if i == 0:
                index[node] = low[node] = counter
                counter += 1
                stack.append(node)
                on_stack.add(node)
            successors = edges[node]
            if i < len(successors):
                work.append((node, i + 1))
                child = successors[i][0]
                if child not in index:
                    work.append((child, 0))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            if low[node] == index[node]:
                number = len(set(component.values()))
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component[member] = number
                    if member == node:
                        break
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
    return component


def _cycle(edges: Mapping[str, list[Dependency]], component: Mapping[str, int], head: str,
           body: str) -> tuple[str, ...]:
    """head, body, ..., head: a shortest way back from `body` to `head` in their component."""
    came_from: dict[str, str] = {body: body}
    frontier = [body]
    while frontier and head not in came_from:
        following = []
        for node in frontier:
            for nxt, _ in edges[node]:
                if component[nxt] == component[head] and nxt not in came_from:
                    came_from[nxt] = node
                    following.append(nxt)
        frontier = following
    path = [head]
    node = head
    while node != body:
        node = came_from[node]
        path.append(node)
    return (head, *reversed(path[1:]), head) if len(path) > 1 else (head, head)
