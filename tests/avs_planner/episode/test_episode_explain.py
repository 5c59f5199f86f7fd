"""The assumption ledger (`episode.explain`): built from hand-made traces, from a real give-up
(the seed's scenario c), for strategies without plans, and printed by `avs explain`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from avs_planner.cli import main
from avs_planner.episode import explain

LEADS = "(assume-leads-to-room placeholder3 kitchen new-room1)"
EXISTS_NEW = "(assume-obj-exists-in cerealbox new-room1 kitchen new-object1)"
CATEGORY = "(assume-category room2 kitchen)"
EXISTS_ROOM2 = "(assume-obj-exists-in cerealbox room2 kitchen new-object1)"


def plan(t: float, why: str, steps: list[str], probs: list[float]) -> dict[str, Any]:
    return {"t": t, "type": "plan", "why": why, "status": "solved" if steps else "unsolvable",
            "plan": steps, "step_p": probs,
            "assumptive": [i for i, s in enumerate(steps) if s.startswith("(assume-")],
            "probability": 0.1 if steps else 0.0}


def found_trace() -> list[dict[str, Any]]:
    """Plan 1 assumes a kitchen behind placeholder3 (its probability rises, then the
    placeholder is explored: refuted); plan 2 assumes room2 is a kitchen, which the classifier
    confirms, and the search there finds the cereal box."""
    return [
        {"t": 0.0, "type": "start", "target": "cerealbox", "world": "office",
         "strategy": "switching", "seed": 4, "robot": "pioneer"},
        plan(5.0, "initial", [LEADS, EXISTS_NEW, "(move place1 placeholder3)",
                              "(move placeholder3 place7)"], [0.3, 0.9, 1.0, 1.0]),
        {"t": 10.0, "type": "action", "action": "(move place1 placeholder3)", "status": "done",
         "detail": ""},
        {"t": 10.0, "type": "monitor", "verdict": "valid", "confirmed": [],
         "assumptions": {LEADS: 0.35, EXISTS_NEW: 0.9}},
        {"t": 20.0, "type": "action", "action": "(move placeholder3 place7)", "status": "done",
         "detail": "explored on the way"},
        {"t": 20.0, "type": "observation", "label": "cerealbox", "detected": False,
         "watching": True, "position": [1.0, 2.0, 0.5]},
        {"t": 20.0, "type": "monitor", "verdict": "assumption_contradicted", "confirmed": [],
         "assumptions": {LEADS: 0.0}},
        {"t": 20.0, "type": "replan", "status": "assumption_contradicted", "action": LEADS,
         "detail": "no longer possible (unreachable or probability 0)"},
        plan(20.0, "replan", [CATEGORY, EXISTS_ROOM2, "(move place7 place9)",
                              "(searchforobject-in cerealbox room2 new-object1 place9)"],
             [0.4, 0.8, 1.0, 0.5]),
        {"t": 30.0, "type": "action", "action": "(move place7 place9)", "status": "done",
         "detail": ""},
        {"t": 30.0, "type": "action", "action": "(classify room2)", "status": "done",
         "detail": "", "category": {"kitchen": 0.97, "office": 0.02}},
        {"t": 30.0, "type": "monitor", "verdict": "probability_changed",
         "confirmed": [CATEGORY], "assumptions": {EXISTS_ROOM2: 0.95}},
        {"t": 30.0, "type": "replan", "status": "probability_changed", "action": EXISTS_ROOM2,
         "detail": "assumption probability changed from 0.8 to 0.95"},
        plan(30.0, "replan", [EXISTS_ROOM2, "(searchforobject-in cerealbox room2 new-object1 "
                                            "place9)"], [0.95, 0.5]),
        {"t": 40.0, "type": "dt", "label": "cerealbox", "relation": "in", "location": "room2",
         "result": "confirmed", "probability": 0.91, "steps": 3, "cones": 2},
        {"t": 40.0, "type": "action", "action": "(searchforobject-in cerealbox room2 "
                                                 "new-object1 place9)", "status": "done",
         "detail": "confirmed object1"},
        {"t": 40.0, "type": "monitor", "verdict": "valid", "confirmed": [EXISTS_ROOM2],
         "assumptions": {}},
        {"t": 41.0, "type": "done", "outcome": "found", "reason": "cerealbox at (1, 2)"},
    ]


def entries(explanation: dict[str, Any]) -> dict[str, list[dict[str, Any]]]:
    out: dict[str, list[dict[str, Any]]] = {}
    for entry in explanation["assumptions"]:
        out.setdefault(entry["action"], []).append(entry)
    return out


def test_the_ledger_follows_each_assumption_to_its_end() -> None:
    explanation = explain.build(found_trace())
    by_action = entries(explanation)
    (leads,) = by_action[LEADS]
    assert leads["status"] == "refuted" and leads["ended_at"] == 20.0
    assert leads["p_first"] == 0.3 and [h["p"] for h in leads["history"]] == [0.35, 0.0]
    assert "placeholder3 was explored" in leads["reason"]
    assert "(move placeholder3 place7) done: explored on the way" in leads["by"]
    assert "cerealbox not confirmed at (1.00, 2.00)" in leads["by"]
    (exists_new,) = by_action[EXISTS_NEW]  # the object assumed in the room behind it falls too
    assert exists_new["status"] == "refuted" and "rests on A1" in exists_new["reason"]
    (category,) = by_action[CATEGORY]
    assert category["status"] == "confirmed" and category["ended_at"] == 30.0
    assert "(classify room2) done (now kitchen 0.97" in category["by"]
    (exists_room2,) = by_action[EXISTS_ROOM2]  # one entry across plans 2 and 3
    assert exists_room2["plans"] == [2, 3] and exists_room2["status"] == "confirmed"
    assert exists_room2["p_first"] == 0.8 and exists_room2["p_last"] == 0.95
    assert "DT search for cerealbox in room2: confirmed" in exists_room2["by"]
    assert explanation["outcome"] == "found" and "give_up" not in explanation


def test_every_replan_has_its_reason() -> None:
    replans = explain.build(found_trace())["replans"]
    assert [(r["verdict"], r["step"]) for r in replans] == [
        ("assumption_contradicted", LEADS), ("probability_changed", EXISTS_ROOM2)]
    assert replans[0]["after"] == "(move placeholder3 place7)"
    assert replans[0]["after_detail"] == "explored on the way"
    assert "from 0.8 to 0.95" in replans[1]["detail"] and replans[1]["assumption"] == "A4"
    assert [p["replan"] for p in explain.build(found_trace())["plans"]] == [None, 1, 2]


def test_a_give_up_names_the_hypotheses_tried_and_why_each_fell() -> None:
    trace = found_trace()[:9] + [
        plan(20.0, "replan", [CATEGORY, EXISTS_ROOM2, "(move place7 place9)"], [0.4, 0.8, 1.0]),
        {"t": 30.0, "type": "action", "action": "(move place7 place9)", "status": "done",
         "detail": ""},
        {"t": 30.0, "type": "monitor", "verdict": "assumption_contradicted", "confirmed": [],
         "assumptions": {CATEGORY: 0.0}},
        {"t": 30.0, "type": "replan", "status": "assumption_contradicted", "action": CATEGORY,
         "detail": "no longer possible (unreachable or probability 0)"},
        plan(30.0, "replan", [], []),
        {"t": 30.0, "type": "done", "outcome": "gave_up", "reason": "no plan"},
    ]
    final = {"rooms": {"room2": {"category": {"office": 0.9, "kitchen": 0.05},
                                 "p_target": 0.02}},
             "placeholders": {}}
    explanation = explain.build(trace, final)
    hypotheses = explanation["give_up"]["hypotheses"]
    assert [h["hypothesis"] for h in hypotheses] == ["a kitchen lies behind placeholder3",
                                                     "room2 is a kitchen"]
    assert all(h["status"] == "refuted" and h["why_dropped"] for h in hypotheses)
    assert hypotheses[0]["p_first"] == 0.3 and hypotheses[0]["p_final"] == 0.0
    assert hypotheses[1]["p_first"] == 0.4 and hypotheses[1]["p_final"] == 0.05  # the mind's
    assert "room2 believed office 0.90" in hypotheses[1]["final_note"]
    (exists,) = entries(explanation)[EXISTS_ROOM2]  # assumed for the kitchen room2 was not
    assert exists["status"] == "refuted" and "rests on A3 (room2 is a kitchen)" in exists["reason"]
    text = explain.render(explanation)
    assert "Room hypotheses tried (2):" in text and "room2 is a kitchen" in text
    assert "planned again (replan): unsolvable" in text


def test_a_strategy_without_plans_gets_what_it_searched_and_why_it_ended() -> None:
    trace = [
        {"t": 0.0, "type": "start", "target": "cup", "world": "office",
         "strategy": "exhaustive", "seed": 0},
        {"t": 5.0, "type": "action", "action": "(explore placeholder2)", "status": "start"},
        {"t": 9.0, "type": "action", "action": "(explore placeholder2)", "status": "done",
         "detail": "explored on the way"},
        {"t": 9.5, "type": "observation", "label": "cup", "detected": False,
         "position": [3.0, 1.0, 0.8]},
        {"t": 20.0, "type": "action", "action": "(sweep room1)", "status": "done",
         "detail": "12 standpoints"},
        {"t": 21.0, "type": "done", "outcome": "gave_up",
         "reason": "explored every reachable placeholder"},
    ]
    explanation = explain.build(trace)
    assert explanation["assumptions"] == [] and explanation["plans"] == []
    assert explanation["search"]["visited"] == {"explore": ["placeholder2"],
                                                "sweep": ["room1"]}
    text = explain.render(explanation)
    assert "exhaustive does not plan with assumptions" in text
    assert "explore: placeholder2 (1)" in text
    assert "ended: gave_up: explored every reachable placeholder" in text


def test_avs_explain_prints_a_run_folder(tmp_path: Path, capsys) -> None:
    with (tmp_path / "trace.jsonl").open("w", encoding="utf-8") as trace:
        for event in found_trace():
            trace.write(json.dumps(event) + "\n")
    assert main(["explain", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "A1 a kitchen lies behind placeholder3 (new-room1)" in text
    assert "refuted at t=20.0 s" in text and "confirmed at t=30.0 s" in text
    assert main(["explain", str(tmp_path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["outcome"] == "found"


@pytest.mark.parametrize(("content", "message"), [
    (None, "neither explanation.json nor trace.jsonl"),
    ('{"t": 0, "type": "start"}\nnot json\n', "trace.jsonl:2: not a JSON event"),
])
def test_avs_explain_names_what_is_wrong(tmp_path: Path, capsys, content, message) -> None:
    if content is not None:
        (tmp_path / "trace.jsonl").write_text(content, encoding="utf-8")
    assert main(["explain", str(tmp_path)]) == 1
    assert message in capsys.readouterr().err
    assert main(["explain", str(tmp_path / "nowhere")]) == 1
    assert "no such run folder" in capsys.readouterr().err


@pytest.mark.slow
def test_scenario_c_explains_every_room_hypothesis_it_gave_up_on(tmp_path: Path) -> None:
    from avs_planner.episode import run_episode
    from avs_planner.episode.scenarios import load_scenario

    spec = dict(load_scenario("c").spec, seed=1, output_dir=str(tmp_path))
    assert run_episode(spec)["outcome"] == "gave_up"
    explanation = json.loads((tmp_path / "explanation.json").read_text(encoding="utf-8"))
    events = explain.read_trace(tmp_path / "trace.jsonl")
    tried = {(step.split()[0][1:], step.split()[1], step.split()[2].rstrip(")"))
             for e in events if e["type"] == "plan" for step in e["plan"]
             if step.startswith(("(assume-leads-to-room", "(assume-category"))}
    hypotheses = explanation["give_up"]["hypotheses"]
    named = {(h["kind"], h["subject"], h["category"]) for h in hypotheses}
    assert tried and named == tried  # every room hypothesis a plan used, none invented
    assert all(h["why_dropped"] and h["status"] in ("refuted", "dropped") for h in hypotheses)
    assert "final_beliefs" in explanation  # the mind's own beliefs at the end
    text = explain.render(explanation)
    for kind, subject, category in tried:
        assert (f"a {category} lies behind {subject}" if kind == "assume-leads-to-room"
                else f"{subject} is a {category}") in text


def test_a_planner_timeout_keeps_the_assumptions_until_the_fallback_plan() -> None:
    trace = found_trace()
    at = next(i for i, e in enumerate(trace) if e["type"] == "plan" and e["why"] == "replan")
    trace.insert(at, {"t": 20.0, "type": "plan", "why": "timeout", "status": "node_limit",
                      "plan": [], "planning_time_s": 20.0})
    explanation = explain.build(trace)
    assert [p["replan"] for p in explanation["plans"]] == [None, 1, 1, 2]
    assert [e["status"] for e in explanation["assumptions"]] == [
        "refuted", "refuted", "confirmed", "confirmed"]
    assert "planned again with the fallback heuristic" in explain.render(explanation)
