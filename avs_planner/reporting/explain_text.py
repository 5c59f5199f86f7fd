"""Explanations as readable text: what `avs explain` prints (the data:
`explain_document.py`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from avs_planner.reporting.explain_terms import distribution_text, with_article


def _p(value: Any) -> str:
    return "?" if value is None else f"{float(value):.3g}"


def _t(value: Any) -> str:
    return "?" if value is None else f"{float(value):.1f} s"


def _room_belief(room: Mapping[str, Any]) -> str:
    """'a kitchen (0.97; office 0.02, bathroom 0.01), P=0.6; objects: table, cerealbox'."""
    dist = room.get("category") or {}
    believed, p = room.get("believed"), room.get("p")
    if believed is None and dist:  # an explanation written before `believed` was recorded
        believed = max(dist, key=lambda k: float(dist[k]))
        p = dist[believed]
    if believed is None:
        text = "no category belief"
    else:
        others = {k: v for k, v in dist.items() if k != believed}
        text = f"{with_article(believed)} ({float(p):.2f}" + (
            f"; {distribution_text(others, 2)})" if others else ")")
    text += f", P={_p(room.get('p_target'))}"
    if room.get("objects"):
        text += "; objects: " + ", ".join(room["objects"])
    return text


def render(explanation: Mapping[str, Any]) -> str:
    """The explanation as readable text (what `avs explain` prints)."""
    e = explanation
    out: list[str] = []
    head = (f"Episode: find {e.get('target')} in {e.get('world')} ({e.get('strategy')}, "
            f"{e.get('robot')}, seed {e.get('seed')})")
    out += [head, f"Outcome: {e.get('outcome')} at t={_t(e.get('t'))}: {e.get('reason')}", ""]
    task = e.get("task")
    if task:
        out.append(f"Task: {task.get('mode')} of {', '.join(task.get('targets') or [])}"
                   + (" (every instance)" if task.get("count") == "all" else "")
                   + f", in {len(task.get('turns') or [])} turns:")
        for turn in task.get("turns") or []:
            watch = f" (also watching {', '.join(turn['watch'])})" if turn.get("watch") else ""
            out.append(f"  t={_t(turn.get('t'))}-{_t(turn.get('ended'))} {turn.get('target')}"
                       f"{watch}: {turn.get('outcome', 'unfinished')}"
                       + (f", {turn['reason']}" if turn.get("reason") else ""))
        for target in task.get("ends") or []:
            out.append(f"  {target.get('target')}: {target.get('outcome')} at "
                       f"t={_t(target.get('t'))}: {target.get('reason')}")
        out.append("")
    plans = e.get("plans") or []
    if plans:
        out.append(f"Plans ({len(plans)}):")
        for plan in plans:
            steps = plan.get("steps") or []
            marked = [("[assume] " if s.get("assumptive") else "") + s["action"]
                      + (f" p={_p(s['p'])}" if s.get("assumptive") and s.get("p") is not None
                         else "") for s in steps]
            if marked:
                body = "; ".join(marked)
            elif plan.get("why") == "timeout":
                body = (f"the planner stopped at its limit ({plan.get('status')}); planned again "
                        f"with the fallback heuristic")
            else:
                body = f"no plan ({plan.get('status')})"
            out.append(f"  #{plan['index']} t={_t(plan.get('t'))} {plan.get('why')}, "
                       f"p={_p(plan.get('probability'))}: {body}")
        out.append("")
    assumptions = e.get("assumptions") or []
    if assumptions:
        out.append(f"Assumptions ({len(assumptions)}):")
        for a in assumptions:
            history = " -> ".join(_p(h["p"]) for h in a.get("history") or [])
            trail = f"p {_p(a.get('p_first'))}" + (f" -> {history}" if history else "")
            out.append(f"  {a['id']} {a['meaning']}: assumed at t={_t(a.get('assumed_at'))} "
                       f"(plan {a.get('plan')}), {trail}")
            line = f"     {a['status']} at t={_t(a.get('ended_at'))}: {a.get('reason')}"
            out.append(line)
            if a.get("by"):
                out.append(f"     by: {a['by']}")
        out.append("")
    replans = e.get("replans") or []
    if replans:
        out.append(f"Replans ({len(replans)}):")
        for r in replans:
            after = f" after {r['after']}" if r.get("after") else ""
            if r.get("after_detail"):
                after += f" ({r['after_detail']})"
            out.append(f"  t={_t(r.get('t'))}{after}: {r.get('summary')}")
        out.append("")
    give_up = e.get("give_up")
    if give_up and plans:
        hyps = give_up.get("hypotheses") or []
        out.append(f"Gave up: {give_up.get('reason')}")
        out.append(f"  Room hypotheses tried ({len(hyps)}):")
        for h in hyps:
            plans_ = ", ".join(str(p) for p in sorted(set(h.get("plans") or [])))
            out.append(f"  - {h['hypothesis']}: p {_p(h.get('p_first'))} when first assumed, "
                       f"final {_p(h.get('p_final'))} (plans {plans_})")
            why = h.get("why_dropped")
            out.append(f"      {h.get('status')} at t={_t(h.get('ended_at'))}: {why}")
            if h.get("by"):
                out.append(f"      by: {h['by']}")
            if h.get("final_note"):
                out.append(f"      at the end: {h['final_note']}")
        if give_up.get("searched"):
            out.append("  Searched: " + "; ".join(give_up["searched"]))
        if give_up.get("then"):
            out.append("  After the last plan:")
            out += [f"    {line}" for line in give_up["then"]]
        out.append("")
    search = e.get("search") or {}
    counts = search.get("action_counts") or {}
    if plans and counts:
        out.append("What it did:")
    if not plans:
        out.append(f"Search ({e.get('strategy')} does not plan with assumptions, so there is "
                   f"no assumption ledger):")
    if counts or not plans:
        if counts:
            out.append("  steps: " + ", ".join(f"{n}x {k}" for k, n in counts.items()))
        for kind, targets in (search.get("visited") or {}).items():
            if kind == "move":
                continue
            out.append(f"  {kind}: {', '.join(targets)} ({len(targets)})")
        for s in search.get("dt_searches") or []:
            out.append(f"  DT search t={_t(s.get('t'))}: {s.get('label')} {s.get('relation')} "
                       f"{s.get('location')}: {s.get('result')} (p {_p(s.get('probability'))})")
        flap = search.get("flap")
        if flap:
            regions = ", ".join(f"{r['name']} (p {_p(r['p'])})" for r in flap["regions"])
            out.append(f"  FLAP: regions {regions or 'none'}; {flap['decisions']} decisions, "
                       f"{flap['views']} views")
            last = flap.get("last_decision")
            if last:
                out.append(f"    last decision (cycle {last['cycle']}): {last['status']}, "
                           f"P(target still unseen in the regions) {_p(last['p_remaining'])}")
        obs = search.get("observations") or {}
        out.append(f"  detections: {obs.get('confirmed', 0)} confirmed, "
                   f"{obs.get('not_confirmed', 0)} not confirmed")
        if not plans:
            out.append(f"  ended: {e.get('outcome')}: {e.get('reason')}")
    final = e.get("final_beliefs") or {}
    if final.get("rooms"):
        out.append("")
        out.append(f"Beliefs at the end (each room's most probable category, P({e.get('target')}"
                   f" in the room), the objects known in it):")
        out += [f"  {rid}: {_room_belief(room)}" for rid, room in final["rooms"].items()]
    notes = e.get("notes") or []
    if notes:
        out.append("")
        out.append("Notes:")
        out += [f"  {n}" for n in notes]
    return "\n".join(out).rstrip() + "\n"
