"""Explanations of an episode: the assumption ledger, the reasons for replans, and give-ups.

Everything here is rebuilt from the episode's trace events (`trace.jsonl`), so any finished run
can be explained again (`avs explain RUN_DIR`). This module is the explanations' front door
(what the harness, the CLI and the service import); each part lives in its own module:

- `explain_ledger.py`: the `Ledger` that follows the trace and every assumption in its plans
  to its end (confirmed, refuted, dropped or unresolved), and `build`;
- `explain_document.py`: what a finished ledger says, as plain data (`explanation.json`);
- `explain_beliefs.py`: the mind's beliefs at the end (`final_beliefs`), which only the
  finished episode knows;
- `explain_files.py`: run folders on disk: `read_trace`, `load`, `write`, `ExplainError`;
- `explain_text.py`: the explanation as readable text (`render`, what `avs explain` prints);
- `explain_terms.py` and `explain_map.py`: the words for assumptions, and the robot's map as
  the trace drew it.

Strategies that do not plan with assumptions (baselines, flap, qsr) get the smaller part every
explanation has: what was searched, what was seen, and why the search ended.
"""

from __future__ import annotations

from avs_planner.reporting.explain_beliefs import final_beliefs
from avs_planner.reporting.explain_document import EXPLANATION_VERSION
from avs_planner.reporting.explain_files import FILE_NAME, ExplainError, load, read_trace, write
from avs_planner.reporting.explain_ledger import Ledger, build
from avs_planner.reporting.explain_text import render

__all__ = ["EXPLANATION_VERSION", "FILE_NAME", "ExplainError", "Ledger", "build",
           "final_beliefs", "load", "read_trace", "render", "write"]
