"""Constructs unified-planning reads but the planner's grounder refuses, found in the text so
that `avs domain check` and `avs plan` report them at the same line and column, naming the
action (or the goal): numeric conditions (the grounder reads numeric fluents only as costs
and probabilities), and conditional effects whose condition is not a conjunction of literals
or whose effect is numeric. What depends on the objects (how many state-dependent conditions
a ground action's effects have) is found by grounding (`cp.grounding.grounding_diagnostics`).
"""

from __future__ import annotations

from avs_planner.pddl.formulas import ASSIGNMENTS, COMPARISONS
from avs_planner.pddl.sexpr import Atom, Node, SList, is_number
from avs_planner.pddl.structure import Action, Report

UNSUPPORTED_CONDITION = "unsupported-condition"
UNSUPPORTED_EFFECT = "unsupported-effect"
_CONNECTIVES = ("and", "or", "not", "imply")
_QUANTIFIERS = ("forall", "exists")
_LITERAL_FORMS = ("and", "not", "or", "imply", "forall", "exists", "=", *COMPARISONS)
_SHOWN = 60  # characters of a construct quoted in a message


def check_action(action: Action, report: Report) -> None:
    """Report what the grounder refuses in one action's precondition and effect."""
    where = f"action '{action.atom.text}'"
    if action.precondition is not None:
        numeric_conditions(action.precondition, report, UNSUPPORTED_CONDITION, where)
    if action.effect is not None:
        _effect(action.effect, report, where, inside_when=False)


def numeric_conditions(node: Node, report: Report, code: str, where: str) -> None:
    """Report each numeric comparison or numeric `=` in a precondition or goal."""
    if not isinstance(node, SList) or not node.items:
        return
    head = node.head()
    if _is_numeric_condition(node):
        report.add(node, code, f"the numeric condition {shown(node)} in {where} is not "
                   "supported (the planner reads numeric fluents only as costs and "
                   "probabilities)")
    elif head in _CONNECTIVES:
        for child in node.items[1:]:
            numeric_conditions(child, report, code, where)
    elif head in _QUANTIFIERS and len(node) == 3:
        numeric_conditions(node.items[2], report, code, where)


def _is_numeric_condition(node: SList) -> bool:
    head = node.head()
    if head in COMPARISONS:
        return True
    return head == "=" and any(isinstance(term, SList) or is_number(term.text)
                               for term in node.items[1:])


def _effect(node: Node, report: Report, where: str, inside_when: bool) -> None:
    if not isinstance(node, SList) or not node.items:
        return
    head = node.head()
    if head == "and":
        for child in node.items[1:]:
            _effect(child, report, where, inside_when)
    elif head in ("forall", "probabilistic") and len(node) == 3:
        _effect(node.items[2], report, where, inside_when)
    elif head == "when" and len(node) == 3:
        _when_condition(node.items[1], report, where)
        _effect(node.items[2], report, where, inside_when=True)
    elif head in ASSIGNMENTS and inside_when:
        report.add(node, UNSUPPORTED_EFFECT, f"the numeric effect {shown(node)} inside a "
                   f"'when' of {where} is not supported (a conditional effect adds or "
                   "deletes atoms)")


def _when_condition(node: Node, report: Report, where: str) -> None:
    """A conditional effect's condition must be a conjunction of literals."""
    if not isinstance(node, SList) or not node.items:
        return
    head = node.head()
    if head == "and":
        for child in node.items[1:]:
            _when_condition(child, report, where)
        return
    inner = node.items[1] if head == "not" and len(node) == 2 else node
    if isinstance(inner, SList) and inner.items and inner.head() not in _LITERAL_FORMS:
        return  # an atom or a negated atom
    report.add(node, UNSUPPORTED_EFFECT, f"the condition {shown(node)} of a conditional "
               f"effect of {where} is not supported (a 'when' condition is a conjunction of "
               "atoms and negated atoms)")


def shown(node: Node) -> str:
    """The node as PDDL text, cut to a readable length."""
    text = _text(node)
    return text if len(text) <= _SHOWN else text[: _SHOWN - 4] + " ...)"


def _text(node: Node) -> str:
    if isinstance(node, Atom):
        return node.text
    return "(" + " ".join(_text(item) for item in node.items) + ")"
