"""`check`: lint a domain and its problems into Diagnostics (what `avs domain check` prints).

The reader runs the same checks first and raises the first error, so a knowledge engineer
gets the same precise position from `avs plan` as from `avs domain check`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from avs_planner.errors import PddlError
from avs_planner.pddl.axioms import check_derived
from avs_planner.pddl.diagnostics import Diagnostic
from avs_planner.pddl.formulas import FormulaChecker, Usage
from avs_planner.pddl.probabilistic import translate_domain
from avs_planner.pddl.problem_checks import NEGATIVE_INIT, check_problem
from avs_planner.pddl.requirements import check_requirements
from avs_planner.pddl.sexpr import parse_sexprs
from avs_planner.pddl.structure import Domain, Report, find_define, read_domain
from avs_planner.pddl.support import UNSUPPORTED_CONDITION, UNSUPPORTED_EFFECT, check_action


@dataclass(frozen=True)
class PddlSource:
    """PDDL text and the name to report it under (a path, or e.g. `<domain>`)."""

    name: str
    text: str

    @classmethod
    def from_path(cls, path: str | Path) -> PddlSource:
        """Read a file; an unreadable file is a PddlError at 1:1."""
        try:
            return cls(str(path), Path(path).read_text(encoding="utf-8-sig"))
        except OSError as exc:
            raise PddlError(f"cannot read file: {exc.strerror or exc}", str(path)) from exc
        except UnicodeDecodeError as exc:
            raise PddlError(f"not a UTF-8 text file ({exc.reason})", str(path)) from exc


Source = PddlSource | str | Path
NAME_CLASH = "name-clash"
# Warnings about what the reader accepts or repairs (what `avs plan` passes on to the user)
LENIENT = {"missing-requirement", NAME_CLASH, "duplicate-type", "either-type", NEGATIVE_INIT}
# Errors about what the planner cannot ground in an action, not about the PDDL: the reader
# still reads the task (other engines may take it); the planner refuses it at that position
NOT_GROUNDED = {UNSUPPORTED_CONDITION, UNSUPPORTED_EFFECT}


@dataclass(frozen=True)
class Checked:
    """`check`'s findings plus the domain read (None when it could not be read)."""

    diagnostics: list[Diagnostic]
    domain: Domain | None = None

    @property
    def first_error(self) -> Diagnostic | None:
        """The first error the reader stops at (not one only the planner stops at)."""
        return next((d for d in self.diagnostics if d.is_error and d.code not in NOT_GROUNDED),
                    None)

    @property
    def not_grounded(self) -> tuple[Diagnostic, ...]:
        """The errors about what the planner cannot ground (`NOT_GROUNDED`)."""
        return tuple(d for d in self.diagnostics if d.is_error and d.code in NOT_GROUNDED)

    @property
    def lenient(self) -> tuple[Diagnostic, ...]:
        """The warnings about what the reader accepted or repaired."""
        return tuple(d for d in self.diagnostics if d.code in LENIENT)


def check(domain: Source, problems: Sequence[Source] = ()) -> list[Diagnostic]:
    """All findings for a domain and its problems; str/Path arguments are file paths."""
    return check_read(domain, problems).diagnostics


def check_read(domain: Source, problems: Sequence[Source] = ()) -> Checked:
    """`check`, keeping the domain it read (for the reader's repairs)."""
    try:
        domain_source = _source(domain)
    except PddlError as exc:
        return Checked([Diagnostic.from_error(exc, "unreadable")])
    report = Report(domain_source.name)
    parsed = _read_domain(domain_source, report)
    if parsed is None:
        return Checked(report.items)
    usage = Usage()
    _check_domain(parsed, report, usage)
    diagnostics = report.items
    for problem in problems:
        try:
            diagnostics += check_problem(parsed, _source(problem), usage)
        except PddlError as exc:
            diagnostics.append(Diagnostic.from_error(exc, "unreadable"))
    diagnostics += check_requirements(parsed, usage)
    diagnostics += _unused_predicates(parsed, usage, report.file)
    return Checked(_sorted(diagnostics), parsed)


def _sorted(diagnostics: list[Diagnostic]) -> list[Diagnostic]:
    """Files in the order given, then by position."""
    order: dict[str, int] = {}
    for d in diagnostics:
        order.setdefault(d.file, len(order))
    return sorted(diagnostics, key=lambda d: (order[d.file], d.line, d.column))


def _source(source: Source) -> PddlSource:
    return source if isinstance(source, PddlSource) else PddlSource.from_path(source)


def _read_domain(source: PddlSource, report: Report) -> Domain | None:
    try:
        nodes = parse_sexprs(source.text, source.name)
        translate_domain(source.text, nodes, source.name)
    except PddlError as exc:
        report.items.append(Diagnostic.from_error(exc))
        return None
    define = find_define(nodes, "domain", report)
    return None if define is None else read_domain(define, report)


def _check_domain(domain: Domain, report: Report, usage: Usage) -> None:
    checker = FormulaChecker(domain, report, dict(domain.constants), usage)
    _check_names(domain, report)
    for entry in domain.constants.values():
        checker.known_type(entry.type_node, entry.type)
    for sig in [*domain.predicates.values(), *domain.functions.values()]:
        for param in sig.params:
            checker.known_type(param.type_node, param.type)
    for action in domain.actions.values():
        scope = _parameters(action.params, checker, report)
        if action.precondition is not None:
            checker.goal(action.precondition, scope)
        if action.effect is not None:
            checker.effect(action.effect, scope)
        check_action(action, report)
    check_derived(domain, report, checker)
    for name, node in usage.changed_functions:
        if name in usage.probability_fluents:
            report.add(
                node,
                "probability-not-static",
                f"'{name}' is a probability fluent, so no action may change it",
            )


def _parameters(params: list, checker: FormulaChecker, report: Report) -> dict[str, str]:
    scope: dict[str, str] = {}
    for param in params:
        if param.name in scope:
            report.add(param.atom, "duplicate", f"parameter '{param.name}' is declared twice")
        checker.known_type(param.type_node, param.type)
        scope[param.name] = param.type
    return scope


def _check_names(domain: Domain, report: Report) -> None:
    """unified-planning keeps one namespace for types, fluents, actions and objects by
    default; the reader lifts that rule (UP's `error_used_name`) when names are shared."""
    seen: dict[str, str] = {name: "type" for name in domain.type_atoms}
    groups = [
        ("predicate", domain.predicates),
        ("function", domain.functions),
        ("action", domain.actions),
        ("constant", domain.constants),
    ]
    for kind, table in groups:
        for name, entry in table.items():
            if name in seen:
                report.add(
                    entry.atom,
                    NAME_CLASH,
                    f"{kind} '{name}' has the same name as a {seen[name]} (read with "
                    f"unified-planning's error_used_name lifted; renaming one is clearer)",
                    warning=True,
                )
            else:
                seen[name] = kind


def _unused_predicates(domain: Domain, usage: Usage, file: str) -> list[Diagnostic]:
    """Predicates nothing reads: no action, goal or derived predicate's rule (a rule's
    head defines its predicate, it does not use it)."""
    report = Report(file)
    derived = domain.derived_names
    for name, sig in domain.predicates.items():
        if name not in usage.predicates:
            what = ("derived predicate", "an action, a goal or another rule") if (
                name in derived) else ("predicate", "an action or goal")
            report.add(
                sig.atom,
                "unused-predicate",
                f"{what[0]} '{name}' is never used by {what[1]}",
                warning=True,
            )
    return report.items
