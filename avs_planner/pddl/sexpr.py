"""A small s-expression reader that keeps 1-based line:column positions for every node.

unified-planning's model objects carry no source positions, so the linter and the
probabilistic pre-pass read the text themselves with this reader.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from avs_planner.errors import PddlError


@dataclass(frozen=True)
class Atom:
    """A symbol or number; `text` is lower-cased (PDDL is case-insensitive)."""

    text: str
    line: int
    column: int
    offset: int

    @property
    def end(self) -> int:
        return self.offset + len(self.text)


@dataclass
class SList:
    """A parenthesised list; `offset`/`end` are the positions of `(` and just after `)`."""

    items: list[Node]
    line: int
    column: int
    offset: int
    end: int = 0
    end_line: int = 0
    end_column: int = 0

    def head(self) -> str:
        """The first item's text if it is an atom, else ''."""
        if self.items and isinstance(self.items[0], Atom):
            return self.items[0].text
        return ""

    def __iter__(self) -> Iterator[Node]:
        return iter(self.items)

    def __len__(self) -> int:
        return len(self.items)


Node = Atom | SList

_DELIMS = set("();")


@dataclass
class _Cursor:
    """Walks the text and tracks line/column."""

    text: str
    file: str
    pos: int = 0
    line: int = 1
    column: int = 1
    stack: list[SList] = field(default_factory=list)

    def advance(self, n: int = 1) -> None:
        for _ in range(n):
            if self.text[self.pos] == "\n":
                self.line += 1
                self.column = 1
            else:
                self.column += 1
            self.pos += 1


def parse_sexprs(text: str, file: str = "<input>") -> list[Node]:
    """Parse all top-level expressions in `text`; unbalanced parentheses raise PddlError."""
    cur = _Cursor(text, file)
    top: list[Node] = []
    while cur.pos < len(text):
        ch = text[cur.pos]
        if ch.isspace():
            cur.advance()
        elif ch == ";":
            while cur.pos < len(text) and text[cur.pos] != "\n":
                cur.advance()
        elif ch == "(":
            cur.stack.append(SList([], cur.line, cur.column, cur.pos))
            cur.advance()
        elif ch == ")":
            _close(cur, top)
        else:
            _append(cur, top, _read_atom(cur))
    if cur.stack:
        opened = cur.stack[-1]
        raise PddlError(
            "unbalanced parentheses: '(' opened here is never closed",
            file,
            opened.line,
            opened.column,
        )
    return top


def _close(cur: _Cursor, top: list[Node]) -> None:
    if not cur.stack:
        raise PddlError("unbalanced parentheses: unexpected ')'", cur.file, cur.line, cur.column)
    node = cur.stack.pop()
    node.end_line, node.end_column = cur.line, cur.column
    cur.advance()
    node.end = cur.pos
    _append(cur, top, node)


def _append(cur: _Cursor, top: list[Node], node: Node) -> None:
    (cur.stack[-1].items if cur.stack else top).append(node)


def _read_atom(cur: _Cursor) -> Atom:
    start, line, column = cur.pos, cur.line, cur.column
    while cur.pos < len(cur.text):
        ch = cur.text[cur.pos]
        if ch.isspace() or ch in _DELIMS:
            break
        cur.advance()
    return Atom(cur.text[start : cur.pos].lower(), line, column, start)


def is_number(text: str) -> bool:
    """True for PDDL numbers (`3`, `0.25`, `-1`) and fractions (`3/10`)."""
    parts = text.split("/")
    if len(parts) > 2:
        return False
    try:
        for part in parts:
            float(part)
    except ValueError:
        return False
    return all(p and p.lstrip("-").replace(".", "", 1).isdigit() for p in parts)
