"""Probabilistic PDDL: unified-planning's reader plus PPDDL's single-outcome `probabilistic`.

`read_files`/`read_text` build a `ProbabilisticProblem`; `check` lints a domain and its
problems into `Diagnostic`s. Every failure is a `PddlError` with file, line and column.
"""

from avs_planner.pddl.check import PddlSource, check
from avs_planner.pddl.diagnostics import Diagnostic, Severity
from avs_planner.pddl.model import ProbabilisticProblem
from avs_planner.pddl.reader import read_files, read_text

__all__ = [
    "Diagnostic",
    "PddlSource",
    "ProbabilisticProblem",
    "Severity",
    "check",
    "read_files",
    "read_text",
]
