"""Linter findings: one `Diagnostic` per problem found, with a stable short code."""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import asdict, dataclass, replace
from enum import StrEnum

from avs_planner.errors import PddlError


class Severity(StrEnum):
    """How bad a finding is: errors make `avs domain check` exit 1, warnings do not."""

    ERROR = "error"
    WARNING = "warning"


@dataclass(frozen=True)
class Diagnostic:
    """A finding at FILE:LINE:COL; `code` is a short stable id such as `unknown-predicate`."""

    file: str
    line: int
    column: int
    severity: Severity
    code: str
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.severity.value}: {self.message}"

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def to_dict(self) -> dict[str, object]:
        data = asdict(self)
        data["severity"] = self.severity.value
        return data

    def as_error(self) -> Diagnostic:
        """The same finding with severity error (`avs domain check --strict`)."""
        return replace(self, severity=Severity.ERROR)

    def to_error(self) -> PddlError:
        return PddlError(self.message, self.file, self.line, self.column)

    @classmethod
    def from_error(cls, error: PddlError, code: str = "syntax") -> Diagnostic:
        return cls(error.file, error.line, error.column, Severity.ERROR, code, error.message)


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """' (did you mean 'x'?)' for the closest candidate, or '' when nothing is close."""
    close = difflib.get_close_matches(name, sorted(set(candidates)), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""
