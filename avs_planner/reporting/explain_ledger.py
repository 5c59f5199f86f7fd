"""The assumption ledger: follows an episode's trace events and every assumption in its plans.

The switching loop records, per plan, every step's probability and which steps are
assumptive (`plan` events), and after every executed step the monitor's verdict with the
probability of each assumption still in the plan and the assumptions that came true
(`monitor` events); `replan` events name the broken step and why.

The ledger follows each assumption (an `assume-*` step, e.g. "a kitchen lies behind
placeholder10") from the plan that first used it: its probability then and at every later
check, and how it ended: **confirmed** (it came true: the monitor dropped it from the plan),
**refuted** (the monitor found it contradicted or impossible), **dropped** (a new plan no
longer used it) or **unresolved** (still assumed when the episode ended). An assumption about a
virtual object (`new-room1`) is tied to the assumption that introduced that object: when the
room hypothesis falls, the object assumed in it falls with it, and the next plan's assumption
of the same name is a new entry. It also keeps what every explanation has, for strategies
that do not plan with assumptions too: the steps done, the DT searches, the detections and
FLAP's decisions. What a finished ledger says is `explain_document.py`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from avs_planner.reporting.explain_document import document
from avs_planner.reporting.explain_map import MapState
from avs_planner.reporting.explain_terms import (
    Assumption,
    action_words,
    describe,
    destination,
    distribution_text,
    evidence,
    is_virtual,
    rounded,
    why_refuted,
    with_article,
)


class Ledger:
    """Consumes trace events one at a time (`feed`), or all at once (`build`)."""

    def __init__(self) -> None:
        self.start: dict[str, Any] = {}
        # a task of several objects: its form, its turns and each target's end (else None/[])
        self.task: dict[str, Any] | None = None
        self.turns: list[dict[str, Any]] = []
        self.targets: list[dict[str, Any]] = []
        self.done: dict[str, Any] | None = None
        self.plans: list[dict[str, Any]] = []
        self.replans: list[dict[str, Any]] = []
        self.assumptions: list[Assumption] = []
        self.open: dict[tuple, Assumption] = {}  # signature -> entry, for the current plan
        self.current: dict[str, tuple] = {}  # label -> signature in the current plan
        self.actions: list[dict[str, Any]] = []
        self.searches: list[dict[str, Any]] = []
        self.observations = {"confirmed": 0, "not_confirmed": 0}
        self.notes: list[str] = []
        self.flap: dict[str, Any] = {"regions": [], "decisions": 0, "views": 0,
                                     "last_decision": None}
        self.since: list[str] = []  # evidence since the last monitor check
        self.last_done: dict[str, Any] | None = None
        self.went_to: dict[str, float] = {}  # move/explore destination -> when it was done
        self._pending_replan: dict[str, Any] | None = None
        self._monitor_evidence: str | None = None
        self.tail: list[str] = []  # what happened since the last plan that was found
        self.events = 0
        self.seen = MapState()  # the robot's map as the trace's `map` events drew it

    # ---- feeding -----------------------------------------------------------------------------

    def feed(self, event: Mapping[str, Any]) -> None:
        self.events += 1
        kind = event.get("type")
        handler = getattr(self, f"_on_{kind}", None)
        text = evidence(event)
        if text is not None:
            self.since.append(text)
            self.tail.append(f"t={float(event.get('t') or 0.0):.1f} s: {text}")
        if handler is not None:
            handler(event)

    def _on_start(self, event: Mapping[str, Any]) -> None:
        self.start = {k: event.get(k) for k in ("target", "world", "robot", "seed", "strategy")}
        task = event.get("task")
        if isinstance(task, Mapping) and task.get("targets"):
            self.task = dict(task)
            self.start["target"] = task_name(task)

    def _on_turn(self, event: Mapping[str, Any]) -> None:
        """A task of several objects searches in turns, one label each (`harness/tasks.py`);
        the assumptions a turn's plans made end with it."""
        if event.get("status") == "start":
            self.turns.append({"t": event.get("t"), "target": event.get("target"),
                               "watch": list(event.get("watch") or [])})
            return
        if self.turns and "ended" not in self.turns[-1]:
            self.turns[-1] |= {"ended": event.get("t"), "outcome": event.get("outcome"),
                               "reason": event.get("reason")}
        for entry in list(self.open.values()):
            self._close(entry, "unresolved", event.get("t"),
                        f"still assumed when the turn for {event.get('target')} ended "
                        f"({event.get('outcome')})")

    def _on_target(self, event: Mapping[str, Any]) -> None:
        self.targets.append({k: event.get(k) for k in ("t", "target", "outcome", "reason",
                                                       "found")})

    def _on_map(self, event: Mapping[str, Any]) -> None:
        self.seen.feed(event)

    def _on_action(self, event: Mapping[str, Any]) -> None:
        if event.get("status") == "start" or not event.get("action"):
            return
        record = {"t": event.get("t"), "action": event.get("action"),
                  "status": event.get("status"), "detail": event.get("detail") or ""}
        self.actions.append(record)
        self.last_done = record
        where = destination(str(record["action"]))
        if where is not None:
            self.went_to[where] = float(record["t"] or 0.0)

    def _on_observation(self, event: Mapping[str, Any]) -> None:
        self.observations["confirmed" if event.get("detected") else "not_confirmed"] += 1

    def _on_dt(self, event: Mapping[str, Any]) -> None:
        self.searches.append({k: event.get(k) for k in
                              ("t", "label", "relation", "location", "result", "probability",
                               "steps", "cones")})

    def _on_belief(self, event: Mapping[str, Any]) -> None:
        if isinstance(event.get("matched"), Mapping):
            self._matched(event["matched"], event.get("t"))
        for key in ("cut_off", "doubt_categories", "retry_blocked", "dropped_support",
                    "most_likely"):
            if key in event:
                text = evidence(event)
                if text is None:  # most_likely: the baselines' next room or placeholder
                    text = (f"most likely {event.get('kind')}: {event['most_likely']} "
                            f"(p {event.get('probability')})")
                self.notes.append(f"t={float(event.get('t', 0.0)):.1f} s: {text}")

    def _on_flap(self, event: Mapping[str, Any]) -> None:
        """FLAP's view planning: the regions searched, its decisions and views."""
        kind = event.get("event")
        if kind == "region":
            self.flap["regions"] = [{"name": v.get("name"), "p": v.get("p")}
                                    for v in event.get("volumes") or []]
        elif kind == "decision":
            self.flap["decisions"] += 1
            self.flap["last_decision"] = {k: event.get(k) for k in
                                          ("t", "cycle", "status", "p_remaining", "planned")}
        elif kind == "view":
            self.flap["views"] += 1

    def _on_plan(self, event: Mapping[str, Any]) -> None:
        steps = list(event.get("plan") or [])
        probs = list(event.get("step_p") or [])
        assumptive = event.get("assumptive")
        flags = ([i in set(assumptive) for i in range(len(steps))] if assumptive is not None
                 else [s.startswith("(assume-") for s in steps])
        index = len(self.plans) + 1
        why = event.get("why", "")
        replan = self._pending_replan
        self._pending_replan = None
        if steps:
            self.tail = []
        else:
            self.tail.append(f"t={float(event.get('t') or 0.0):.1f} s: planned again ({why}): "
                             f"{event.get('status')}")
        self.plans.append({
            "index": index, "t": event.get("t"), "why": why, "status": event.get("status"),
            "probability": event.get("probability"), "cost": event.get("cost"),
            "steps": [{"action": s, "p": probs[i] if i < len(probs) else None,
                       "assumptive": flags[i]} for i, s in enumerate(steps)],
            "replan": replan["index"] if replan else None,
        })
        if why == "timeout" and not steps:  # the CP hit its node or time limit
            self._pending_replan = replan  # the fallback search follows at once and
            return  # answers the same replan; the old plan's entries stay till then
        signatures = self._signatures([s for s, a in zip(steps, flags, strict=False) if a])
        keep = set(signatures.values())
        cause = (f"plan {index} ({why}) no longer uses it" if steps else
                 f"no plan found ({event.get('status')}) when planning {why}")
        if replan is not None and steps:
            cause += f"; replanned because {replan['summary']}"
        for sig, entry in list(self.open.items()):
            if sig not in keep and sig in self.open:
                self._close(entry, "dropped", event.get("t"), cause)
        self.current = {}
        for i, step in enumerate(steps):
            if not flags[i]:
                continue
            sig = signatures[step]
            p = probs[i] if i < len(probs) else None
            entry = self.open.get(sig)
            if entry is None:
                meaning, about = describe(step)
                name = action_words(step)[0] if action_words(step) else step
                entry = Assumption(f"A{len(self.assumptions) + 1}", step, meaning, name,
                                   event.get("t"), index, rounded(p), plans=[index], **about)
                self.assumptions.append(entry)
                self.open[sig] = entry
            else:
                entry.plans.append(index)
                if p is not None and (entry.p_last is None or abs(entry.p_last - p) > 1e-4):
                    entry.history.append({"t": event.get("t"), "p": rounded(p),
                                          "source": f"plan {index}"})
            self.current[step] = sig

    @staticmethod
    def _signatures(steps: list[str]) -> dict[str, tuple]:
        """An assumption's identity: its label and the identities of the earlier assumptions
        it rests on: those that introduced the virtual objects it mentions, and the one that
        gave its room the category it assumes an object for."""
        introduced: dict[Any, tuple] = {}
        out: dict[str, tuple] = {}
        for step in steps:
            name, *args = action_words(step) or [""]
            uses: list[Any] = [n for n in args if is_virtual(n)]
            if name == "assume-obj-exists-in" and len(args) == 4:
                uses.append(("category", args[1], args[2]))
            elif name == "assume-obj-exists-on" and len(args) == 6:
                uses.append(("category", args[4], args[3]))
            deps: list[tuple] = []
            for key in uses:
                if key in introduced and introduced[key] not in deps:
                    deps.append(introduced[key])
            sig = (step, tuple(deps))
            out[step] = sig
            provides: list[Any] = [n for n in args if is_virtual(n)]
            if name == "assume-category" and len(args) == 2:
                provides.append(("category", args[0], args[1]))
            elif name == "assume-leads-to-room" and len(args) == 3:
                provides.append(("category", args[2], args[1]))
            for key in provides:
                introduced.setdefault(key, sig)
        return out

    def _matched(self, matched: Mapping[str, str], t: Any) -> None:
        """A real object matched a virtual one: the assumption that introduced the virtual
        object came true; the plan's other steps now name the real object."""
        evidence = "; ".join(self.since) if self.since else "a detection"
        for virtual, real in matched.items():
            for entry in list(self.open.values()):
                names = action_words(entry.action)[1:]
                if entry.kind.startswith("assume-obj-exists") and names[-1:] == [virtual]:
                    self._close(entry, "confirmed", t, f"{virtual} matched {real}: a "
                                f"{entry.label} was found there", evidence)
        renamed: dict[str, tuple] = {}
        for label, sig in self.current.items():
            words = action_words(label)
            new = "(" + " ".join(matched.get(w, w) for w in words) + ")"
            renamed[label] = sig
            if new != label:
                renamed[new] = sig
        self.current = renamed

    def _entry(self, label: str | None) -> Assumption | None:
        sig = self.current.get(label) if label else None
        return self.open.get(sig) if sig is not None else None

    def _on_monitor(self, event: Mapping[str, Any]) -> None:
        t = event.get("t")
        evidence = self._evidence_now()
        for label in event.get("confirmed") or []:
            entry = self._entry(label)
            if entry is not None:
                self._close(entry, "confirmed", t, "it came true", evidence)
        for label, p in (event.get("assumptions") or {}).items():
            entry = self._entry(label)
            if entry is None:
                continue
            if entry.p_last is None or abs(entry.p_last - float(p)) > 1e-4:
                entry.history.append({"t": t, "p": rounded(p), "source": "monitor"})
        self._monitor_evidence = evidence

    def _evidence_now(self) -> str:
        text = "; ".join(self.since) if self.since else "no new observation"
        self.since = []
        return text

    def _on_replan(self, event: Mapping[str, Any]) -> None:
        t = event.get("t")
        verdict = event.get("status") or ""
        step = event.get("action")
        detail = event.get("detail") or ""
        evidence = getattr(self, "_monitor_evidence", None) or self._evidence_now()
        self._monitor_evidence = None
        after = self.last_done
        summary = f"{verdict.replace('_', ' ')}: {step}" + (f" ({detail})" if detail else "")
        record = {"index": len(self.replans) + 1, "t": t, "verdict": verdict, "step": step,
                  "detail": detail, "after": after["action"] if after else None,
                  "after_detail": after["detail"] if after else None, "evidence": evidence,
                  "plan_before": len(self.plans), "summary": summary}
        entry = self._entry(step)
        if entry is not None:
            record["assumption"] = entry.id
            if verdict == "assumption_contradicted":
                if entry.p_last != 0.0:
                    entry.history.append({"t": t, "p": 0.0, "source": "monitor"})
                status, why = self._behind(entry, t, evidence) or (
                    "refuted", why_refuted(entry, detail or verdict, self.went_to))
                self._close(entry, status, t, why, evidence)
        self.replans.append(record)
        self._pending_replan = record

    def _behind(self, entry: Assumption, t: Any, evidence: str) -> tuple[str, str] | None:
        """A room hypothesis about a placeholder the robot mapped the space behind, judged
        by what it found there: the objects it detected there since the hypothesis was made
        (within `FOUND_REACH` of where the placeholder last stood), the room it mapped there
        (the room of the place nearest that spot, else the room it put those objects in) and
        that room's believed category. An object of an assumption resting on the hypothesis
        found there makes that assumption come true, whatever the category. None when the
        map shows nothing there (the placeholder vanished unvisited)."""
        if entry.kind != "assume-leads-to-room" or entry.subject is None:
            return None
        since = float(entry.assumed_at or 0.0)
        objects = self.seen.found_near(entry.subject, since)
        room = self.seen.room_behind(entry.subject)
        if room is None and objects:
            rooms = [o[4] for o in objects if o[4] is not None]
            room = max(set(rooms), key=rooms.count) if rooms else None
        if room is None:
            return None
        sig = next((s for s, e in self.open.items() if e is entry), None)
        for other_sig, other in list(self.open.items()):
            if sig is None or sig not in other_sig[1] or other is entry \
                    or not other.kind.startswith("assume-obj-exists") or not other.label:
                continue
            match = [o for o in objects if o[1] == other.label
                     and float(self.seen.since[o[0]]) >= float(other.assumed_at or 0.0)]
            if match:
                oid, label, x, y, where = match[0]
                self._close(other, "confirmed", t, f"{with_article(label)} was found there: "
                            f"{oid} at ({x:.2f}, {y:.2f}), in {where}", evidence)
        found = ""
        if objects:
            labels = list(dict.fromkeys(o[1] for o in objects))
            found = " (found there: " + ", ".join(with_article(x) for x in labels) + ")"
        mapped = (f"{entry.subject} was explored{found}: the space behind it is {room}"
                  + ("" if self.seen.new_since(room, since)
                     else ", a room mapped before it was assumed"))
        belief = self.seen.rooms.get(room) or {}
        if not belief:
            return "refuted", f"{mapped}, which has no category belief yet"
        top = max(belief, key=lambda k: float(belief[k]))
        believed = f"believed {distribution_text(belief, 3)}"
        if top == entry.category:
            return "confirmed", f"{mapped}, {believed}"
        return "refuted", f"{mapped}, {believed}: not {with_article(str(entry.category))}"

    def _on_done(self, event: Mapping[str, Any]) -> None:
        self.done = {"t": event.get("t"), "outcome": event.get("outcome"),
                     "reason": event.get("reason")}
        for entry in list(self.open.values()):
            self._close(entry, "unresolved", event.get("t"),
                        f"still assumed when the episode ended ({event.get('outcome')})")

    def _close(self, entry: Assumption, status: str, t: Any, reason: str,
               by: str | None = None) -> None:
        entry.status, entry.ended_at, entry.reason = status, t, reason
        entry.by = by
        sig = next((s for s, e in self.open.items() if e is entry), None)
        if sig is None:
            return
        del self.open[sig]
        if status == "confirmed":  # what rests on it now rests on a fact
            self._rekey(sig)
        if status in ("refuted", "dropped"):  # what rests on it falls with it
            for other_sig, other in list(self.open.items()):
                if sig in other_sig[1]:
                    if status == "refuted":
                        other.history.append({"t": t, "p": 0.0, "source": "monitor"})
                    self._close(other, status, t, f"rests on {entry.id} ({entry.meaning}), "
                                f"which was {status}", by)

    def _rekey(self, fact: tuple) -> None:
        """An assumption came true: the entries resting on it no longer do (a next plan
        without it continues them)."""
        for sig, entry in list(self.open.items()):
            if fact in sig[1]:
                new = (sig[0], tuple(d for d in sig[1] if d != fact))
                del self.open[sig]
                self.open[new] = entry
                self.current = {k: new if v == sig else v for k, v in self.current.items()}

    # ---- the explanation ---------------------------------------------------------------------

    def explanation(self, final: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The explanation as plain data (`explain_document.py`); `final` holds the mind's
        beliefs at the end (rooms with category beliefs and P(target), placeholders), when
        known."""
        return document(self, final)


def build(events: Iterable[Mapping[str, Any]], final: Mapping[str, Any] | None = None
          ) -> dict[str, Any]:
    """The explanation of a whole trace."""
    ledger = Ledger()
    for event in events:
        ledger.feed(event)
    return ledger.explanation(final)


def task_name(task: Mapping[str, Any]) -> str:
    """A task of several objects in a few words ("cup and book", "cup or glass", "every
    chair"), as its summary names it (`harness.tasks.TaskForm.name`)."""
    labels = [str(t) for t in task.get("targets") or []]
    if task.get("count") == "all" and labels:
        return f"every {labels[0]}"
    if len(labels) < 2:
        return labels[0] if labels else "?"
    joint = " or " if task.get("mode") == "any" else " and "
    return ", ".join(labels[:-1]) + joint + labels[-1]
