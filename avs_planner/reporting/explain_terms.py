"""The assumptions of an explanation and the words for them: what an `assume-*` step means
("a kitchen lies behind placeholder10"), what observation settled it, and why it was refuted
(the ledger itself: `explain_ledger.py`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Assumption:
    """One assumption's life in the ledger."""

    id: str
    action: str
    meaning: str
    kind: str
    assumed_at: float
    plan: int  # the plan that first used it (1-based)
    p_first: float | None
    history: list[dict[str, Any]] = field(default_factory=list)  # {t, p, source}
    plans: list[int] = field(default_factory=list)
    status: str = "open"  # open | confirmed | refuted | dropped | unresolved
    ended_at: float | None = None
    by: str | None = None  # the observation that settled it
    reason: str | None = None
    subject: str | None = None  # the room or placeholder it is about
    category: str | None = None
    label: str | None = None  # the object label it is about (obj-exists)

    @property
    def p_last(self) -> float | None:
        return self.history[-1]["p"] if self.history else self.p_first


def action_words(label: str) -> list[str]:
    return label.strip().strip("()").split()


def is_virtual(name: str) -> bool:
    return name.startswith("new-")


def with_article(noun: str) -> str:
    return f"{'an' if noun[:1].lower() in 'aeiou' else 'a'} {noun}"


def describe(action: str) -> tuple[str, dict[str, str | None]]:
    """What an assumptive step assumes, in words, and its subject, category and label."""
    name, *args = action_words(action) or [""]
    if name == "assume-leads-to-room" and len(args) == 3:
        return (f"{with_article(args[1])} lies behind {args[0]} ({args[2]})",
                {"subject": args[0], "category": args[1], "label": None})
    if name == "assume-category" and len(args) == 2:
        return f"{args[0]} is {with_article(args[1])}", {"subject": args[0], "category": args[1],
                                                "label": None}
    if name == "assume-obj-exists-in" and len(args) == 4:
        return (f"{with_article(args[0])} is in {args[1]} (as {with_article(args[2])}) ({args[3]})",
                {"subject": args[1], "category": args[2], "label": args[0]})
    if name == "assume-obj-exists-on" and len(args) == 6:
        return (f"{with_article(args[0])} is on {args[1]} ({with_article(args[2])} in "
                f"{args[4]}, as {with_article(args[3])}) ({args[5]})",
                {"subject": args[1], "category": args[3], "label": args[0]})
    return f"{action} holds", {"subject": args[0] if args else None, "category": None,
                               "label": None}


def evidence(event: Mapping[str, Any]) -> str | None:
    """One event as evidence, in words (None for events that say nothing new)."""
    kind = event.get("type")
    if kind == "action" and event.get("status") not in (None, "start"):
        detail = event.get("detail") or ""
        text = f"{event.get('action')} {event.get('status')}" + (f": {detail}" if detail else "")
        category = event.get("category")
        if isinstance(category, Mapping) and category:
            text += " (now " + distribution_text(category) + ")"
        return text
    if kind == "observation":
        where = event.get("position")
        at = f" at ({where[0]:.2f}, {where[1]:.2f})" if isinstance(where, list | tuple) and \
            len(where) >= 2 else ""
        seen = "confirmed" if event.get("detected") else "not confirmed"
        if event.get("detected") is False and not at:
            return None  # a look that saw nothing: the dt event sums these up
        return f"{event.get('label')} {seen}{at}"
    if kind == "dt":
        return (f"DT search for {event.get('label')} {event.get('relation')} "
                f"{event.get('location')}: {event.get('result')} after {event.get('steps')} "
                f"steps (p {event.get('probability')})")
    if kind == "belief":
        if "blocked" in event:
            return f"blocked: {event.get('detail')}"
        if "doubt_categories" in event:
            return (f"room categories believed below {event['doubt_categories']} doubted "
                    f"again ({event.get('reason')})")
        if "retry_blocked" in event:
            return f"blocked spots tried again: {', '.join(event['retry_blocked'])}"
        if "cut_off" in event:
            return "cut off: " + "; ".join(event["cut_off"])
        if "dropped_support" in event:
            return f"support label {event['dropped_support']} dropped ({event.get('reason')})"
        if "matched" in event:
            return "matched " + ", ".join(f"{k} = {v}" for k, v in event["matched"].items())
    return None


def destination(action: str) -> str | None:
    """Where a move or explore step went."""
    words = action_words(action)
    if len(words) == 3 and words[0] == "move":
        return words[2]
    if len(words) == 2 and words[0] == "explore":
        return words[1]
    return None


def why_refuted(entry: Assumption, detail: str, went_to: Mapping[str, float]) -> str:
    """The monitor's verdict on a contradicted assumption, read with where the robot went."""
    if entry.kind == "assume-leads-to-room" and "no longer possible" in detail:
        if went_to.get(entry.subject or "", -math.inf) >= float(entry.assumed_at or 0.0):
            return (f"{entry.subject} was explored (the robot went there): it is no longer "
                    f"a placeholder, so no unseen {entry.category} can be assumed behind it "
                    f"(monitor: {detail})")
        return (f"{entry.subject} is no longer a placeholder (the map grew over it), so no "
                f"unseen {entry.category} can be assumed behind it (monitor: {detail})")
    if entry.kind == "assume-category" and "no longer possible" in detail:
        return (f"the planner no longer offers {entry.category} for {entry.subject}: its "
                f"category belief is taken as settled, or the room changed as the map grew "
                f"(monitor: {detail})")
    if entry.kind.startswith("assume-obj-exists") and "defined-exists" in detail:
        where = "in" if entry.kind == "assume-obj-exists-in" else "on"
        return (f"{with_article(entry.label or 'object')} may no longer be assumed {where} "
                f"{entry.subject}: the searches there came back empty (or one was found "
                f"there already) (monitor: {detail})")
    return f"monitor: {detail}"


def distribution_text(category: Mapping[str, Any], n: int = 2) -> str:
    """The `n` likeliest entries of a distribution: 'office 0.93, kitchen 0.02'."""
    items = sorted(category.items(), key=lambda kv: -float(kv[1]))[:n]
    return ", ".join(f"{k} {float(v):.2f}" for k, v in items)


def rounded(value: Any) -> float | None:
    return None if value is None else round(float(value), 4)
