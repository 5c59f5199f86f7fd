"""The explanation as plain data: what a finished assumption ledger says about its episode.

The outcome, every plan and replan, every assumption's life, what was searched (steps done,
places visited, DT searches, detections, FLAP's decisions), the notes; for a give-up, the
room hypotheses tried with their first and final probability and why each was dropped; and a
few summary lines. This is what `explanation.json` holds (`explain_files.py`) and what
`avs explain` prints (`explain_text.py`); the ledger that gathers it: `explain_ledger.py`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from avs_planner.reporting.explain_terms import action_words, distribution_text, rounded

if TYPE_CHECKING:
    from avs_planner.reporting.explain_ledger import Ledger

EXPLANATION_VERSION = 1


def document(ledger: Ledger, final: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The explanation as plain data; `final` holds the mind's beliefs at the end
    (rooms with category beliefs and P(target), placeholders), when known."""
    outcome = ledger.done or {"t": None, "outcome": "unfinished",
                              "reason": "the trace has no done event"}
    out: dict[str, Any] = {
        "version": EXPLANATION_VERSION, **ledger.start, **outcome,
        "events": ledger.events,
        "plans": ledger.plans, "replans": ledger.replans,
        "assumptions": [asdict(a) | {"p_last": a.p_last} for a in ledger.assumptions],
        "search": _search(ledger),
        "notes": ledger.notes,
    }
    if ledger.task is not None:
        out["task"] = {**ledger.task, "turns": ledger.turns, "ends": ledger.targets}
    if final:
        out["final_beliefs"] = dict(final)
    if outcome["outcome"] == "gave_up":
        out["give_up"] = _give_up(ledger, final)
    out["summary"] = _summary(ledger, out)
    return out


def _search(ledger: Ledger) -> dict[str, Any]:
    """What was searched: the steps done and their counts, the places each kind of step
    went to, the DT searches, the detections, and FLAP's decisions when it made any."""
    kinds: dict[str, int] = {}
    visited: dict[str, list[str]] = {}  # explore -> placeholders, sweep -> rooms, ...
    for a in ledger.actions:
        words = action_words(a["action"]) or [a["action"]]
        kinds[words[0]] = kinds.get(words[0], 0) + 1
        target = words[-1] if len(words) > 1 else None
        if target is not None and words[0] in ("explore", "sweep", "classify", "move"):
            seen = visited.setdefault(words[0], [])
            if target not in seen:
                seen.append(target)
    out = {"actions": ledger.actions, "action_counts": kinds, "visited": visited,
           "dt_searches": ledger.searches, "observations": dict(ledger.observations)}
    if ledger.flap["decisions"] or ledger.flap["regions"]:
        out["flap"] = dict(ledger.flap)
    return out


def _give_up(ledger: Ledger, final: Mapping[str, Any] | None) -> dict[str, Any]:
    """The room hypotheses tried (where a plan assumed the target could be) with their
    first and final probability and why each was dropped; the rooms searched."""
    rooms = (final or {}).get("rooms") or {}
    placeholders = (final or {}).get("placeholders")
    hypotheses: dict[tuple, dict[str, Any]] = {}
    for a in ledger.assumptions:
        if a.kind not in ("assume-leads-to-room", "assume-category"):
            continue
        key = (a.kind, a.subject, a.category)
        h = hypotheses.get(key)
        if h is None:
            h = hypotheses[key] = {
                "hypothesis": a.meaning.split(" (new-")[0], "kind": a.kind,
                "subject": a.subject, "category": a.category, "assumptions": [],
                "plans": [], "p_first": a.p_first}
        h["assumptions"].append(a.id)
        h["plans"] += a.plans
        h["p_last"] = a.p_last
        h["status"], h["why_dropped"], h["by"], h["ended_at"] = (
            a.status, a.reason, a.by, a.ended_at)
        posterior = None
        if a.kind == "assume-category" and a.subject in rooms:
            posterior = (rooms[a.subject].get("category") or {}).get(a.category)
            h["final_note"] = f"{a.subject} believed " + distribution_text(
                rooms[a.subject].get("category") or {}, 3)
        elif a.kind == "assume-leads-to-room" and placeholders is not None:
            if a.subject in placeholders:
                posterior = (placeholders[a.subject].get("category") or {}).get(a.category)
            else:
                h["final_note"] = f"{a.subject} was explored (no longer a placeholder)"
                posterior = 0.0
        h["p_final"] = rounded(posterior) if posterior is not None else h["p_last"]
    searched = [f"{s['label']} {s['relation']} {s['location']}: {s['result']}"
                for s in ledger.searches]
    if not ledger.plans:  # a strategy without plans: what it went through is the story
        return {"reason": (ledger.done or {}).get("reason"), "hypotheses": [],
                "searched": searched, "then": []}
    return {"reason": (ledger.done or {}).get("reason"),
            "hypotheses": list(hypotheses.values()), "searched": searched,
            "then": list(ledger.tail)}


def _summary(ledger: Ledger, out: Mapping[str, Any]) -> list[str]:
    """A few lines: the episode and its outcome, the plans and assumptions, the give-up."""
    lines = [f"{out.get('target')} in {out.get('world')} ({out.get('strategy')}, seed "
             f"{out.get('seed')}): {out.get('outcome')}: {out.get('reason')}"]
    if ledger.plans:
        counts: dict[str, int] = {}
        for a in ledger.assumptions:
            counts[a.status] = counts.get(a.status, 0) + 1
        lines.append(f"{len(ledger.plans)} plans, {len(ledger.replans)} replans, "
                     f"{len(ledger.assumptions)} assumptions ("
                     + ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) + ")")
    if "give_up" in out:
        hyps = out["give_up"]["hypotheses"]
        lines.append(f"gave up after trying {len(hyps)} room hypotheses: " + "; ".join(
            f"{h['hypothesis']} ({h['status']})" for h in hyps))
    return lines
