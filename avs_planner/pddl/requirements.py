"""Requirement flags: which are known, which imply which, and used-versus-declared checks."""

from __future__ import annotations

from avs_planner.pddl.diagnostics import Diagnostic, did_you_mean
from avs_planner.pddl.formulas import Usage
from avs_planner.pddl.sexpr import Node, SList
from avs_planner.pddl.structure import Domain, Report

QUANTIFIED = {":universal-preconditions", ":existential-preconditions"}
IMPLIES: dict[str, set[str]] = {
    ":adl": {
        ":strips",
        ":typing",
        ":negative-preconditions",
        ":disjunctive-preconditions",
        ":equality",
        ":quantified-preconditions",
        ":conditional-effects",
        *QUANTIFIED,
    },
    ":quantified-preconditions": QUANTIFIED,
    ":fluents": {":numeric-fluents", ":object-fluents", ":action-costs"},
    ":numeric-fluents": {":action-costs"},
}
# Valid PDDL flags the planner cannot read (`:derived-predicates`, which unified-planning's
# reader does not take either, is read by the project's own model, `lite`).
UNSUPPORTED = {":object-fluents"}
KNOWN = {
    *IMPLIES[":adl"],
    ":adl",
    ":fluents",
    ":numeric-fluents",
    ":object-fluents",
    ":action-costs",
    ":probabilistic-effects",
    ":durative-actions",
    ":duration-inequalities",
    ":timed-initial-literals",
    ":derived-predicates",
    ":constraints",
    ":preferences",
}


def closure(declared: set[str]) -> set[str]:
    """Every requirement granted by the declared ones."""
    granted = set(declared)
    for flag in declared:
        granted |= IMPLIES.get(flag, set())
    return granted


def check_requirements(domain: Domain, usage: Usage) -> list[Diagnostic]:
    """Unknown flags (errors); flags used but not declared, declared but unused (warnings:
    Fast Downward reads such domains, and so do we)."""
    report = Report(domain.file)
    declared = {atom.text for atom in domain.requirements}
    _unknown(domain, report)
    _typing_usage(domain, usage)
    granted = closure(declared)
    for flag, (file, node) in usage.requirements.items():
        if flag not in granted:
            where = Report(file)
            where.add(node, "missing-requirement", _missing_message(node, flag), warning=True)
            report.items += where.items
    _unused(domain, usage, report)
    return report.items


def _missing_message(node: Node, flag: str) -> str:
    construct = node.head() if isinstance(node, SList) else node.text
    return (f"'{construct}' needs requirement {flag}, which the domain does not declare "
            f"(read as if it did)")


def _unknown(domain: Domain, report: Report) -> None:
    for atom in domain.requirements:
        if atom.text in UNSUPPORTED:
            report.add(
                atom,
                "unsupported-requirement",
                f"requirement {atom.text} is valid PDDL but avs-planner cannot read it",
            )
        elif atom.text not in KNOWN:
            hint = did_you_mean(atom.text, KNOWN)
            report.add(atom, "unknown-requirement", f"unknown requirement '{atom.text}'{hint}")


def _typing_usage(domain: Domain, usage: Usage) -> None:
    if domain.uses_typing is not None:
        usage.need(":typing", domain.file, domain.uses_typing)


def _unused(domain: Domain, usage: Usage, report: Report) -> None:
    used = set(usage.requirements)
    for atom in domain.requirements:
        if atom.text == ":strips" or atom.text not in KNOWN or atom.text in UNSUPPORTED:
            continue
        if not ({atom.text} | IMPLIES.get(atom.text, set())) & used:
            report.add(
                atom,
                "unused-requirement",
                f"requirement {atom.text} is declared but nothing uses it",
                warning=True,
            )
