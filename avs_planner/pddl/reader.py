"""Read a probabilistic PDDL domain + problem into a `ProbabilisticProblem`.

Order: our own checks first (they know positions), then the probabilistic pre-pass, then
the model of the translated text. That is the project's own (`lite`, built by
`up_builder.build_lite`, without importing unified-planning) where it takes the text, with
the UP problem of the same text built when someone asks for it (`ProbabilisticProblem.problem`;
a domain with derived predicates, which only `lite` reads, has none: asking raises);
else UP's (`_up_parse`: the fast builder, else UP's PDDLReader), and whatever UP still rejects
becomes a `PddlError` with the position UP or pyparsing reported.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from fractions import Fraction
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from avs_planner.errors import PddlError, SourcePosition
from avs_planner.pddl import lite
from avs_planner.pddl.check import NAME_CLASH, PddlSource, check_read
from avs_planner.pddl.model import ProbabilisticProblem, SourceMap
from avs_planner.pddl.probabilistic import translate_domain
from avs_planner.pddl.sexpr import Atom, Node, SList, is_number, parse_sexprs
from avs_planner.pddl.structure import Domain, Report, find_define, read_problem
from avs_planner.pddl.up_builder import build_lite, build_problem

if TYPE_CHECKING:
    from unified_planning.model import Action, FNode, Problem

_UP_POSITION = re.compile(r"line:?\s*(\d+),\s*col:?\s*(\d+)", re.IGNORECASE)


def read_files(domain_path: str | Path, problem_path: str | Path) -> ProbabilisticProblem:
    """Read a domain file and a problem file; raises PddlError naming file, line and column."""
    return read_text(
        _read(domain_path),
        _read(problem_path),
        domain_name=str(domain_path),
        problem_name=str(problem_path),
    )


def read_text(
    domain_text: str,
    problem_text: str,
    domain_name: str = "<domain>",
    problem_name: str = "<problem>",
) -> ProbabilisticProblem:
    """Read domain and problem text (e.g. from the HTTP service) into a ProbabilisticProblem."""
    checked = check_read(
        PddlSource(domain_name, domain_text), [PddlSource(problem_name, problem_text)]
    )
    error = checked.first_error
    if error is not None:
        raise error.to_error()
    domain_nodes = parse_sexprs(domain_text, domain_name)
    translation = translate_domain(domain_text, domain_nodes, domain_name)
    repairs = checked.domain.repairs if checked.domain is not None else []
    text = apply_repairs(translation.text, repairs)
    shared = any(d.code == NAME_CLASH for d in checked.lenient)
    up_read = partial(_up_read, text, problem_text, shared, translation.probabilities,
                      domain_name, problem_name)
    derived = checked.domain.derived if checked.domain is not None else []
    read = _lite_read(text, problem_text, shared, translation.probabilities, domain_name)
    if read is None or isinstance(read, Exception):
        if derived:  # UP's reader does not take `:derived` either: say so, at the rule
            raise _derived_error(derived[0].node, domain_name,
                                 f"the project's model does not take this text ({read})")
        read = up_read()
    elif derived:
        read[0].counterpart = partial(_no_counterpart, derived[0].node, domain_name)
    else:
        read[0].counterpart = up_read  # the UP problem, when someone asks for it
    model, success = read
    sources = _sources(checked.domain, problem_text, domain_name, problem_name)
    return ProbabilisticProblem(model, success, domain_name, problem_name, checked.lenient,
                                sources, checked.not_grounded)


def _up_read(domain: str, problem_text: str, shared: bool, probabilities: Mapping[str, list],
             domain_name: str, problem_name: str) -> tuple[Problem, dict[str, FNode]]:
    """UP's problem of the (translated, repaired) text and its success expressions."""
    with _names_shared(shared):
        problem = _up_parse(domain, problem_text, domain_name, problem_name)
    success = {name: _success_expression(problem, name, nodes, domain_name)
               for name, nodes in probabilities.items()}
    return problem, success


def _lite_read(domain: str, problem_text: str, shared: bool,
               probabilities: Mapping[str, list], domain_name: str
               ) -> tuple[lite.Problem, dict[str, Any]] | Exception | None:
    """The project's own model of the text and its success expressions, or why not (None:
    no reason given) where UP reads it (a construct `lite` leaves to UP, or anything UP
    would refuse: UP's reading then reports it as before). A probability our own code
    refuses (a `PddlError`) is refused alike either way."""
    try:
        model = build_lite(domain, problem_text, shared)
        success = {name: _success_expression(model, name, nodes, domain_name)
                   for name, nodes in probabilities.items()}
    except PddlError:
        raise
    except Exception as exc:  # noqa: BLE001 - Unsupported, ModelError, ...: UP reads it
        return exc
    return model, success


def _derived_error(rule: SList, domain_name: str, why: str) -> PddlError:
    return PddlError(f"derived predicates (:derived) are read by avs-planner's own model "
                     f"only, and {why}", domain_name, rule.line, rule.column)


def _no_counterpart(rule: SList, domain_name: str) -> tuple[Problem, dict[str, FNode]]:
    """What `ProbabilisticProblem.problem` raises for a domain with derived predicates."""
    raise _derived_error(rule, domain_name, "unified-planning's model (1.3) has no derived "
                         "predicates: this task has no unified-planning problem (its engines "
                         "and plan validators cannot take it)")


def _sources(domain: Domain | None, problem_text: str, domain_name: str, problem_name: str
             ) -> SourceMap:
    """Where each action's name, each derived predicate's first rule and the goal (and each
    of its conjuncts) are written."""
    actions = {} if domain is None else {
        name: SourcePosition(domain_name, a.atom.line, a.atom.column)
        for name, a in domain.actions.items()}
    rules: dict[str, SourcePosition] = {}
    for rule in domain.derived if domain is not None else ():
        rules.setdefault(rule.atom.text, SourcePosition(domain_name, rule.node.line,
                                                        rule.node.column))
    report = Report(problem_name)  # the text passed the checks: nothing is reported here
    define = find_define(parse_sexprs(problem_text, problem_name), "problem", report)
    goal = None if define is None else read_problem(define, report).goal
    if goal is None:
        return SourceMap(actions, rules=rules)
    parts = [SourcePosition(problem_name, n.line, n.column) for n in _conjuncts(goal)]
    return SourceMap(actions, SourcePosition(problem_name, goal.line, goal.column),
                     tuple(parts), rules)


def _conjuncts(node: Node) -> list[Node]:
    """The goal's conjuncts with nested `and`s flattened, as the grounder reads them."""
    if isinstance(node, SList) and node.head() == "and":
        return [c for child in node.items[1:] for c in _conjuncts(child)]
    return [node]


def apply_repairs(text: str, repairs: list[tuple[int, int, str]]) -> str:
    """Replace each `text[start:end]` by its replacement padded with spaces: offsets, and so
    UP's own line:column reports, stay right."""
    chars = list(text)
    for start, end, replacement in repairs:
        padded = replacement.ljust(end - start)
        chars[start:end] = [c if old != "\n" else old for c, old in zip(padded, text[start:end],
                                                                      strict=True)]
    return "".join(chars)


@contextmanager
def _names_shared(shared: bool) -> Iterator[None]:
    """Let a type, predicate and action share a name (IPC floortile's `up`, freecell's
    `suit`) by lifting UP's `error_used_name` while reading. UP's reader builds the metric
    in the global environment, so the flag is lifted there, and restored after."""
    from unified_planning.environment import get_environment

    environment = get_environment()
    before = environment.error_used_name
    environment.error_used_name = before and not shared
    try:
        with warnings.catch_warnings():  # our own name-clash warning says it, with a position
            warnings.filterwarnings("ignore", "Name .* already defined", UserWarning)
            yield
    finally:
        environment.error_used_name = before


def _read(path: str | Path) -> str:
    try:
        return Path(path).read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise PddlError(f"cannot read file: {exc.strerror or exc}", str(path), 1, 1) from exc
    except UnicodeDecodeError as exc:
        raise PddlError(f"not a UTF-8 text file ({exc.reason})", str(path), 1, 1) from exc


def _up_parse(domain: str, problem: str, domain_name: str, problem_name: str) -> Problem:
    """The UP `Problem` of the (translated, repaired) text: built directly by `up_builder`
    when it takes the text (30-90x faster than UP's pyparsing reader, the same
    Problem), else read by UP's `PDDLReader`, whose errors become `PddlError`s."""
    built = _fast_build(domain, problem)
    if built is not None:
        return built
    from unified_planning.io import PDDLReader

    try:
        return PDDLReader().parse_problem_string(domain, problem)
    except Exception as exc:  # noqa: BLE001 - UP raises many kinds; all become PddlError
        file = domain_name if _domain_fails(domain) else problem_name
        raise _convert(exc, file) from exc


def _fast_build(domain: str, problem: str) -> Problem | None:
    """`up_builder`'s Problem, or None to read with UP's reader: for a construct the builder
    leaves to UP, and for any error on the way (UP's reader then reports it, as before).
    Warnings the model gave are shown only if the build is kept, so a fallback does not
    show them twice."""
    with warnings.catch_warnings(record=True) as caught:
        try:
            built = build_problem(domain, problem)
        except Exception:  # noqa: BLE001 - Unsupported, or what the model rejects
            return None
    for warning in caught:
        warnings.warn_explicit(warning.message, warning.category, warning.filename,
                               warning.lineno)
    return built


def _domain_fails(domain: str) -> bool:
    """Which file UP's complaint is about: the domain if it fails on its own."""
    from unified_planning.io import PDDLReader

    try:
        PDDLReader().parse_problem_string(domain, None)
    except Exception:  # noqa: BLE001
        return True
    return False


def _convert(exc: Exception, file: str) -> PddlError:
    import pyparsing

    if isinstance(exc, pyparsing.ParseBaseException):
        return PddlError(f"syntax error: {exc.msg}", file, exc.lineno, exc.col)
    message = str(exc).strip() or type(exc).__name__
    match = _UP_POSITION.search(message)
    line, col = (int(match.group(1)), int(match.group(2))) if match else (1, 1)
    first = message.splitlines()[0]
    return PddlError(f"unified-planning cannot read this: {first}", file, line, col)


def _success_expression(problem: Problem, action: str, nodes: list[Node], file: str) -> FNode:
    """The product of an action's probability terms, as an expression of the problem's
    model (UP's, or `lite`'s: the same calls)."""
    em = problem.environment.expression_manager
    up_action = problem.action(action)
    factors = [_term(problem, up_action, node, file) for node in nodes]
    if len(factors) == 1:
        return factors[0]
    return problem.environment.simplifier.simplify(em.Times(*factors))


def _term(problem: Problem, action: Action, node: Node, file: str) -> FNode:
    em = problem.environment.expression_manager
    if isinstance(node, Atom):
        if not is_number(node.text):
            raise PddlError(
                f"probability must be a number, a fraction or a fluent term, not '{node.text}'",
                file,
                node.line,
                node.column,
            )
        return em.Real(Fraction(node.text))
    return _fluent_term(problem, action, node, file)


def _fluent_term(problem: Problem, action: Action, node: SList, file: str) -> FNode:
    name = node.head()
    if not name or not problem.has_fluent(name):
        raise PddlError(f"unknown function '{name}' in probability", file, node.line, node.column)
    fluent = problem.fluent(name)
    args = []
    for arg in node.items[1:]:
        if not isinstance(arg, Atom):
            raise PddlError("probability arguments must be names", file, arg.line, arg.column)
        if arg.text.startswith("?"):
            args.append(_parameter_exp(action, arg, file))
        elif problem.has_object(arg.text):
            args.append(problem.environment.expression_manager.ObjectExp(problem.object(arg.text)))
        else:
            raise PddlError(f"unknown object '{arg.text}'", file, arg.line, arg.column)
    return problem.environment.expression_manager.FluentExp(fluent, args)


def _parameter_exp(action: Action, arg: Atom, file: str) -> FNode:
    """A UP parameter expression for `?name` of `action`."""
    name = arg.text[1:]
    for param in action.parameters:
        if param.name == name:
            return action.environment.expression_manager.ParameterExp(param)
    raise PddlError(f"variable '{arg.text}' is not a parameter", file, arg.line, arg.column)
