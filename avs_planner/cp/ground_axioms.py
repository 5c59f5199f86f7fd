"""Ground derived predicates' rules over fact ids, and the closure of a state under them.

A state of a task with rules holds its basic facts and, always, the derived facts they
imply: the least fixpoint of the rules, stratum by stratum (`close`). The search closes
every successor (the Python engine here, the C core with the same rules packed by
`native_args`), so applicability, the goal test and conditional effects (copies of an
action whose conditions are plain preconditions) read derived facts as any other. Actions
never change derived facts (the reader refuses it), so a successor's basic part is the
action's effect on the parent's and only the derived part is computed again.

A rule is `head <- pos, not neg, clauses`: fact ids, with clauses (`(pos, neg)`: some pos
fact true or some neg fact false) where a `forall` or a kept disjunction grounded to more
than one literal. Within a stratum, negative literals name basic facts or derived facts of
lower strata (fixed when the stratum starts), so the stratum's rules are monotone and
evaluated semi-naively: every rule once, then only the rules reading a fact just derived.

For the relaxed heuristics each rule is an auxiliary relaxed action of weight 0
(`relaxed_merge.with_rules`): its positive unit literals are its preconditions, its head
its effect; its negative literals and clauses are taken as satisfied (an over-approximation,
as the delete relaxation takes negative preconditions: h^max stays admissible).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from functools import cached_property
from typing import NamedTuple

import numpy as np

from avs_planner.cp.fact_rows import bitset
from avs_planner.cp.ground_structure import GroundStructure
from avs_planner.cp.task import GroundAction, fact_ids

Clause = tuple[tuple[int, ...], tuple[int, ...]]


class GroundRule(NamedTuple):
    """`head` holds where every `pos` fact does, no `neg` fact does and every clause
    holds; `stratum` orders the rules' evaluation."""

    head: int
    pos: tuple[int, ...]
    neg: tuple[int, ...]
    clauses: tuple[Clause, ...]
    stratum: int


class GroundAxioms:
    """A task's ground rules, sorted by stratum, and its derived facts (immutable once
    built)."""

    def __init__(self, rules: Iterable[GroundRule], derived: Iterable[int] = ()):
        self.rules: tuple[GroundRule, ...] = tuple(sorted(rules, key=lambda r: r.stratum))
        bounds = [0]
        for i in range(1, len(self.rules)):
            if self.rules[i].stratum != self.rules[i - 1].stratum:
                bounds.append(i)
        self.strata: tuple[int, ...] = (*bounds, len(self.rules)) if self.rules else (0,)
        self.derived: tuple[int, ...] = tuple(sorted({*derived, *(r.head for r in self.rules)}))
        """The facts of derived predicates: those the rules derive, and those they can never
        derive (false in every state, yet read by a rule or an action)."""
        self.mask = bitset(self.derived)
        """`derived` as a bitset: cleared before a state is closed again."""

    def __len__(self) -> int:
        return len(self.rules)

    def __repr__(self) -> str:
        return f"GroundAxioms({len(self.rules)} rules, {len(self.strata) - 1} strata)"

    # ---- the closure ------------------------------------------------------------------

    @cached_property
    def _compiled(self) -> tuple[list[tuple[int, int, int, tuple[tuple[int, int], ...]]],
                                 list[tuple[int, int, dict[int, list[int]]]]]:
        """Per rule (head bit, pos mask, neg mask, clause masks); per stratum (start, stop,
        the stratum's rules reading each of its heads positively)."""
        rules = [(1 << r.head, bitset(r.pos), bitset(r.neg),
                  tuple((bitset(p), bitset(n)) for p, n in r.clauses)) for r in self.rules]
        strata = []
        for start, stop in zip(self.strata[:-1], self.strata[1:], strict=True):
            heads = {self.rules[i].head for i in range(start, stop)}
            readers: dict[int, list[int]] = {}
            for i in range(start, stop):
                rule = self.rules[i]
                read = set(rule.pos).union(*(p for p, _ in rule.clauses)) & heads
                for fact in read:
                    readers.setdefault(fact, []).append(i)
            strata.append((start, stop, readers))
        return rules, strata

    def close(self, state: int) -> int:
        """`state`'s basic facts and every derived fact they imply (derived facts given in
        `state` are dropped first: the rules decide them)."""
        state &= ~self.mask
        rules, strata = self._compiled
        for start, stop, readers in strata:
            agenda: Iterable[int] = range(start, stop)
            while agenda:
                derived = []
                for i in agenda:
                    head, pos, neg, clauses = rules[i]
                    if state & head or state & pos != pos or state & neg:
                        continue
                    if clauses and not all(state & p or n & ~state for p, n in clauses):
                        continue
                    state |= head
                    derived.append(self.rules[i].head)
                agenda = sorted({j for f in derived for j in readers.get(f, ())})
        return state

    # ---- what the rules read ----------------------------------------------------------

    @cached_property
    def _support(self) -> dict[int, int]:
        """Per derived fact, every fact its value depends on (through other derived facts
        too), as a bitset."""
        direct: dict[int, int] = {}
        for r in self.rules:
            read = bitset(r.pos) | bitset(r.neg)
            for p, n in r.clauses:
                read |= bitset(p) | bitset(n)
            direct[r.head] = direct.get(r.head, 0) | read
        support = dict(direct)
        changed = True
        while changed:  # transitive closure over derived facts (few rounds: the strata)
            changed = False
            for head, read in support.items():
                wider = read
                for f in fact_ids(read & self.mask):
                    wider |= support.get(f, 0)
                if wider != read:
                    support[head] = wider
                    changed = True
        return support

    def expanded_reads(self, reads: int) -> int:
        """`reads` with every fact the derived facts among them depend on."""
        derived = reads & self.mask
        if not derived:
            return reads
        support = self._support
        for f in fact_ids(derived):
            reads |= support.get(f, 0)
        return reads

    def commutes(self, a: GroundAction, b: GroundAction) -> bool:
        """`GroundAction.commutes_with`, with what the rules read: an action reading a
        derived fact reads every fact it depends on (actions never write derived facts)."""
        w1, w2 = a.add | a.delete, b.add | b.delete
        r1, r2 = self.expanded_reads(a.reads), self.expanded_reads(b.reads)
        return not (r1 & w2 or r2 & w1 or a.add & b.delete or a.delete & b.add)

    def facts(self) -> set[int]:
        """Every fact a rule names, and every derived fact."""
        found: set[int] = set(self.derived)
        for r in self.rules:
            found.add(r.head)
            found.update(r.pos, r.neg, *(f for clause in r.clauses for f in clause))
        return found

    def remap(self, new_of: Sequence[int]) -> GroundAxioms:
        """The rules over renumbered facts (`new_of[old]`; every named fact kept)."""
        def ids(facts: tuple[int, ...]) -> tuple[int, ...]:
            return tuple(new_of[f] for f in facts)
        return GroundAxioms((GroundRule(new_of[r.head], ids(r.pos), ids(r.neg),
                                        tuple((ids(p), ids(n)) for p, n in r.clauses),
                                        r.stratum) for r in self.rules), ids(self.derived))

    # ---- packed for others ------------------------------------------------------------

    def relaxed(self) -> tuple[list[tuple[int, ...]], list[tuple[int, ...]]]:
        """Preconditions and add effects of the rules as relaxed actions (see the module
        docstring: positive unit literals only)."""
        return [r.pos for r in self.rules], [(r.head,) for r in self.rules]

    def native_args(self) -> np.ndarray:
        """The rules as one int64 array for the C core (`_native_axioms.h`, `axioms_parse`):
        n_strata, n_rules, n_clauses, n_derived, strata offsets (n_strata + 1), heads, the
        derived facts, then CSRs (offsets, values) of pos, neg, each rule's clauses, and each
        clause's pos and neg."""
        rules = self.rules
        clauses = [c for r in rules for c in r.clauses]

        def csr(lists: list[tuple[int, ...]]) -> list[int]:
            return [*np.cumsum([0, *map(len, lists)]).tolist(), *(x for xs in lists
                                                                for x in xs)]
        parts = [len(self.strata) - 1, len(rules), len(clauses), len(self.derived),
                 *self.strata, *(r.head for r in rules), *self.derived,
                 *csr([r.pos for r in rules]), *csr([r.neg for r in rules]),
                 *np.cumsum([0, *(len(r.clauses) for r in rules)]).tolist(),
                 *csr([p for p, _ in clauses]), *csr([n for _, n in clauses])]
        return np.array(parts, dtype="<i8")


def rules_of_rows(st: GroundStructure, rows: np.ndarray, derived: frozenset[str]
                  ) -> GroundAxioms:
    """The ground rules of these rows of a grounding structure (rows of rule schemas): head
    from `add`, body from `pre`, `pre_neg` and the row's clauses; the structure's facts of
    the `derived` predicates."""
    n = len(st.facts)
    starts = np.array([b.start for b in st.blocks], dtype=np.int64)
    block_of = (np.searchsorted(starts, rows, side="right") - 1).tolist()
    heads, pos, neg = st.add[rows].tolist(), st.pre[rows].tolist(), st.pre_neg[rows].tolist()
    found = []
    for k, row in enumerate(rows.tolist()):
        (head,) = {f for f in heads[k] if f < n}
        found.append(GroundRule(head, tuple(sorted({f for f in pos[k] if f < n})),
                                tuple(sorted({f for f in neg[k] if f < n})),
                                tuple(st.clauses.get(row, ())),
                                st.blocks[block_of[k]].schema.stratum))
    return GroundAxioms(found, (i for i, atom in enumerate(st.facts) if atom[0] in derived))
