"""The one exception root of `avs_planner`, with a subclass per kind of failure.

Callers (CLI, HTTP service) catch `AvsError` and map its subclasses to exit codes or HTTP
statuses; nothing below this package knows about either.
"""

from __future__ import annotations

from dataclasses import dataclass


class AvsError(Exception):
    """Root of every error the planning package raises on purpose."""


@dataclass(frozen=True)
class SourcePosition:
    """Where in a source file something is (1-based line and column)."""

    file: str
    line: int
    column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


class PddlError(AvsError):
    """Bad PDDL input: carries file, line, column and a message (`FILE:LINE:COL: message`)."""

    def __init__(self, message: str, file: str = "<input>", line: int = 1, column: int = 1):
        self.message = message
        self.file = file
        self.line = line
        self.column = column
        super().__init__(f"{file}:{line}:{column}: {message}")

    @property
    def position(self) -> SourcePosition:
        return SourcePosition(self.file, self.line, self.column)


class PlanningError(AvsError):
    """A planner could not run (bad options, unsupported problem kind)."""
