"""The assumption ledger (`reporting.explain`): built from hand-made traces, from a real give-up
(scenario c of the active visual search paper), for strategies without plans, and printed by
`avs explain`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from avs_planner.cli import main
from avs_planner.reporting import explain

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
    from avs_planner.harness import run_episode
    from avs_planner.harness.scenarios import load_scenario

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


LEADS5 = "(assume-leads-to-room placeholder5 kitchen new-room1)"
EXISTS5 = "(assume-obj-exists-in cerealbox new-room1 kitchen new-object1)"


def seen_behind_trace(room: str, belief: dict[str, float],
                      places: list[list[Any]]) -> list[dict[str, Any]]:
    """The Fig. 3a run of the active visual search paper (Göbelbecker et al.), as
    `avs simulate --scenario a --seed 1` traced it: plan 5 assumes a kitchen behind placeholder5;
    on the way there the robot sees a table, a counter and the cereal box through the doorway
    (the mind puts them in `room`), placeholder5 vanishes, and the monitor calls the room
    hypothesis impossible."""
    corridor = {"corridor": 0.9, "office": 0.1}
    return [
        {"t": 0.0, "type": "start", "target": "cerealbox", "world": "office",
         "strategy": "switching", "seed": 1, "robot": "pioneer"},
        {"t": 0.0, "type": "map", "pose": [6.0, 3.2, 0.0],
         "places": [["place1", 6.0, 3.2, "room1"]],
         "placeholders": [["placeholder5", 2.03, 4.03]], "rooms": {"room1": corridor},
         "objects": [["object1", "table", 9.0, 5.21, "room1"]]},
        plan(129.4, "replan", [LEADS5, EXISTS5, "(move place15 placeholder5)",
                               "(createviewcones-in cerealbox new-room1)",
                               "(searchforobject-in cerealbox new-room1 new-object1 "
                               "placeholder5)", "(reportposition new-object1 cerealbox)"],
             [0.124, 0.924, 1.0, 1.0, 0.5, 1.0]),
        {"t": 129.4, "type": "action", "action": "(move place15 placeholder5)",
         "status": "start"},
        {"t": 166.4, "type": "map", "pose": [3.06, 3.56, 3.0],
         "placeholders": [["placeholder5", 1.53, 4.68]]},
        {"t": 171.2, "type": "observation", "label": "table", "detected": True,
         "watching": True, "position": [1.99, 6.02, 0.27], "object": "object2"},
        {"t": 173.2, "type": "observation", "label": "cerealbox", "detected": True,
         "watching": True, "position": [2.16, 5.84, 0.93]},
        {"t": 173.2, "type": "action", "action": "(move place15 placeholder5)",
         "status": "done", "detail": "saw the target on the way"},
        {"t": 173.2, "type": "map", "pose": [2.14, 3.79, 2.0], "places": places,
         "placeholders": [], "rooms": {"room1": corridor, room: belief},
         "objects": [["object1", "table", 9.0, 5.21, "room1"],
                     ["object2", "table", 1.99, 6.02, room],
                     ["object4", "cerealbox", 2.16, 5.84, room]]},
        {"t": 173.2, "type": "monitor", "verdict": "assumption_contradicted", "confirmed": [],
         "assumptions": {LEADS5: 0.0}},
        {"t": 173.2, "type": "replan", "status": "assumption_contradicted", "action": LEADS5,
         "detail": "no longer possible (unreachable or probability 0)"},
        plan(173.2, "replan", ["(reportposition object4 cerealbox)"], [1.0]),
        {"t": 174.3, "type": "action", "action": "(reportposition object4 cerealbox)",
         "status": "found", "detail": "cerealbox at (2.16, 5.84, 0.93)"},
        {"t": 174.3, "type": "done", "outcome": "found", "reason": "cerealbox at (2.16, 5.84)"},
    ]


def test_a_room_hypothesis_is_confirmed_by_the_kitchen_and_box_found_behind_it() -> None:
    """The robot mapped a room behind placeholder5 that it believes a kitchen, with the box in
    it: both assumptions came true, though the placeholder is gone (the monitor's verdict)."""
    trace = seen_behind_trace("room4", {"kitchen": 0.97, "corridor": 0.02},
                              [["place1", 6.0, 3.2, "room1"], ["place18", 2.91, 3.56, "room1"],
                               ["place19", 1.9, 4.9, "room4"]])
    by_action = entries(explain.build(trace))
    (leads,) = by_action[LEADS5]
    assert leads["status"] == "confirmed" and leads["ended_at"] == 173.2
    assert "the space behind it is room4, believed kitchen 0.97" in leads["reason"]
    assert "found there: a table, a cerealbox" in leads["reason"]
    (exists,) = by_action[EXISTS5]
    assert exists["status"] == "confirmed"
    assert "a cerealbox was found there: object4 at (2.16, 5.84), in room4" in exists["reason"]


def test_a_box_found_where_the_map_merged_the_kitchen_into_the_corridor() -> None:
    """No door recognised: the kitchen's floor is part of the corridor's room1 (believed a
    corridor). The box assumed behind placeholder5 was found there (confirmed); the kitchen,
    by the robot's own belief, was not (refuted, naming the room and its belief)."""
    trace = seen_behind_trace("room1", {"corridor": 0.61, "kitchen": 0.13},
                              [["place1", 6.0, 3.2, "room1"], ["place18", 2.91, 3.56, "room1"]])
    explanation = explain.build(trace)
    by_action = entries(explanation)
    (leads,) = by_action[LEADS5]
    assert leads["status"] == "refuted"
    assert ("the space behind it is room1, a room mapped before it was assumed, believed "
            "corridor 0.61, kitchen 0.13: not a kitchen") in leads["reason"]
    (exists,) = by_action[EXISTS5]
    assert exists["status"] == "confirmed" and "object4" in exists["reason"]
    assert "rests on" not in exists["reason"]
    assert explanation["outcome"] == "found"


def test_a_placeholder_that_vanished_unvisited_keeps_the_monitors_reason() -> None:
    """No place near where it stood and nothing found there: the old reading stands."""
    trace = seen_behind_trace("room1", {"corridor": 0.61}, [["place1", 6.0, 3.2, "room1"]])
    trace = [e for e in trace if not (e["type"] == "map" and e["t"] == 173.2)]
    (leads,) = entries(explain.build(trace))[LEADS5]
    assert leads["status"] == "refuted" and "placeholder5 was explored" in leads["reason"]
    assert "no unseen kitchen can be assumed behind it" in leads["reason"]


def test_the_final_beliefs_name_each_room_with_its_most_probable_category() -> None:
    final = {"rooms": {"room1": {"believed": "corridor", "p": 0.61,
                                 "category": {"corridor": 0.61, "kitchen": 0.13,
                                              "office": 0.1},
                                 "p_target": 1.0, "objects": ["table", "cerealbox"]},
                       "room2": {"category": {"office": 0.97, "corridor": 0.03},
                                 "p_target": 0.0064}},  # written before `believed`
             "placeholders": {}}
    text = explain.render(explain.build(found_trace(), final))
    assert "room1: a corridor (0.61; kitchen 0.13, office 0.10), P=1; objects: table, " \
           "cerealbox" in text
    assert "room2: an office (0.97; corridor 0.03), P=0.0064" in text
