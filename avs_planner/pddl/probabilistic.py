"""Translate PPDDL's single-outcome `(probabilistic P E)` away before unified-planning reads.

The wrapper tokens `(probabilistic P` and the matching `)` are overwritten with spaces, so
every other character keeps its offset and UP's own line:column reports stay right. The
probability expressions are returned per action, as s-expression nodes, for the reader to
turn into UP expressions once the problem exists.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from avs_planner.errors import PddlError
from avs_planner.pddl.sexpr import Atom, Node, SList

PROBABILISTIC = "probabilistic"
REQUIREMENT = ":probabilistic-effects"


@dataclass
class Translation:
    """The UP-readable text plus each action's probability expressions (a product)."""

    text: str
    probabilities: dict[str, list[Node]] = field(default_factory=dict)


def translate_domain(text: str, nodes: list[Node], file: str) -> Translation:
    """Blank out probabilistic wrappers and the `:probabilistic-effects` requirement."""
    chars = list(text)
    result = Translation(text)
    define = _define(nodes)
    if define is None:
        return result
    for section in define.items[2:]:
        if not isinstance(section, SList):
            continue
        head = section.head()
        if head == ":requirements":
            _blank_requirement(section, chars)
        elif head == ":action":
            name, probs = _action_probabilities(section, chars, file)
            if probs:
                result.probabilities[name] = probs
    result.text = "".join(chars)
    return result


def _define(nodes: list[Node]) -> SList | None:
    for node in nodes:
        if isinstance(node, SList) and node.head() == "define":
            return node
    return None


def _blank(chars: list[str], start: int, end: int) -> None:
    for i in range(start, end):
        if chars[i] not in "\n":
            chars[i] = " "


def _blank_requirement(section: SList, chars: list[str]) -> None:
    for item in section.items[1:]:
        if isinstance(item, Atom) and item.text == REQUIREMENT:
            _blank(chars, item.offset, item.end)


def _action_probabilities(action: SList, chars: list[str], file: str) -> tuple[str, list[Node]]:
    name = action.items[1].text if len(action) > 1 and isinstance(action.items[1], Atom) else ""
    items = action.items
    for i, item in enumerate(items[:-1]):
        if isinstance(item, Atom) and item.text == ":effect":
            return name, _effect_probabilities(items[i + 1], chars, file, top=True)
    return name, []


def _effect_probabilities(node: Node, chars: list[str], file: str, top: bool) -> list[Node]:
    """Collect and blank `(probabilistic P E)` at the top of an effect or inside its `and`."""
    if not isinstance(node, SList):
        return []
    head = node.head()
    if head == PROBABILISTIC:
        if not top:
            raise PddlError(
                "a probabilistic effect must be the action's whole effect or directly inside "
                "its top-level (and ...)",
                file,
                node.line,
                node.column,
            )
        return [_unwrap(node, chars, file)]
    found: list[Node] = []
    for child in node.items[1:]:
        found += _effect_probabilities(child, chars, file, top=top and head == "and")
    return found


def _unwrap(node: SList, chars: list[str], file: str) -> Node:
    if len(node) != 3:
        raise PddlError(
            "only single-outcome (probabilistic P EFFECT) is supported; "
            f"found {len(node) - 1} argument(s)",
            file,
            node.line,
            node.column,
        )
    prob, effect = node.items[1], node.items[2]
    if isinstance(effect, SList) and _contains_probabilistic(effect):
        inner = _first_probabilistic(effect)
        raise PddlError("nested probabilistic effects are not supported", file, *inner)
    _blank(chars, node.offset, prob.end if isinstance(prob, Atom) else prob.end)
    _blank(chars, node.end - 1, node.end)
    return prob


def _contains_probabilistic(node: SList) -> bool:
    return _first_probabilistic(node) != (0, 0)


def _first_probabilistic(node: SList) -> tuple[int, int]:
    if node.head() == PROBABILISTIC:
        return node.line, node.column
    for child in node.items:
        if isinstance(child, SList):
            found = _first_probabilistic(child)
            if found != (0, 0):
                return found
    return 0, 0
