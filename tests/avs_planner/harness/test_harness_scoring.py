"""The robot's map scored against the world file (`harness.scoring`): the pure scoring on
hand-made maps with known answers, and `map_score` in a real episode's summary."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from avs_planner.harness.runner import run_episode
from avs_planner.harness.scoring import RobotMap, TrueRoom, score_map

# the built-in office world's rooms (sim/worlds/office.yaml)
OFFICE = [
    TrueRoom("corridor", "corridor", (0.0, 2.5, 12.0, 4.0)),
    TrueRoom("kitchen", "kitchen", (0.0, 4.0, 4.5, 8.0)),
    TrueRoom("office1", "office", (4.5, 4.0, 12.0, 8.0)),
    TrueRoom("office2", "office", (4.0, 0.0, 12.0, 2.5)),
]
RES = 0.1


def cells_in(rect: tuple[float, float, float, float], inset: float = 0.15) -> np.ndarray:
    """Cell centres on a 0.1 m grid inside the rectangle less `inset` (walls, clutter)."""
    x0, y0, x1, y1 = rect
    xs = np.arange(x0 + inset, x1 - inset, RES) + RES / 2
    ys = np.arange(y0 + inset, y1 - inset, RES) + RES / 2
    gx, gy = np.meshgrid(xs, ys)
    return np.stack([gx.ravel(), gy.ravel()], axis=1)


def robot_map(owners: dict[str, list[str]], beliefs: dict[str, dict[str, float]],
              unowned: tuple[str, ...] = ()) -> RobotMap:
    """A robot map whose room `rid` holds the free cells of the true rooms `owners[rid]`."""
    by_name = {t.name: t for t in OFFICE}
    cells, owner = [], []
    for rid, names in owners.items():
        for name in names:
            pts = cells_in(by_name[name].rect)
            cells.append(pts)
            owner += [rid] * len(pts)
    for name in unowned:  # mapped free space that no robot room holds
        pts = cells_in(by_name[name].rect)
        cells.append(pts)
        owner += [None] * len(pts)
    return RobotMap(np.vstack(cells), owner, RES * RES, beliefs)


def through(*points: tuple[float, float]) -> list[tuple[float, float, float]]:
    return [(x, y, 0.0) for x, y in points]


# the robot drove along the corridor into office1 and office2, never into the kitchen
PATH = through((6.0, 3.2), (7.0, 3.3), (7.0, 5.5), (7.0, 3.3), (10.0, 3.3), (10.0, 1.2))


def sure(category: str, p: float = 0.9) -> dict[str, float]:
    return {category: p, "other": 1.0 - p}


def test_a_perfect_map_scores_one() -> None:
    robot = robot_map({"room1": ["corridor"], "room2": ["kitchen"], "room3": ["office1"],
                       "room4": ["office2"]},
                      {"room1": sure("corridor"), "room2": sure("kitchen"),
                       "room3": sure("office"), "room4": sure("office", 0.6)})
    score = score_map(OFFICE, robot, PATH + through((2.0, 5.0)))
    assert score["rooms_true"] == score["rooms_robot"] == score["rooms_matched"] == 4
    assert score["merges"] == score["splits"] == 0
    assert score["entered_rooms"] == 4 and score["category_accuracy"] == 1.0
    assert score["entered_area_m2"] == pytest.approx(18 + 18 + 30 + 20)
    assert all(r["matched"] and r["iou"] == 1.0 for r in score["rooms"])
    by_name = {r["name"]: r for r in score["rooms"]}
    assert by_name["office2"] == {**by_name["office2"], "robot_room": "room4",
                                  "believed": "office", "p": 0.6, "category": "office"}


def test_a_kitchen_merged_into_the_corridor_counts_a_merge_and_one_match_fewer() -> None:
    robot = robot_map({"room1": ["corridor", "kitchen"], "room3": ["office1"],
                       "room4": ["office2"]},
                      {"room1": sure("corridor"), "room3": sure("office"),
                       "room4": sure("office")})
    score = score_map(OFFICE, robot, PATH + through((2.0, 5.0)))
    assert score["merges"] == 1 and score["splits"] == 0
    assert score["rooms_matched"] == 3 and score["rooms_robot"] == 3
    by_name = {r["name"]: r for r in score["rooms"]}
    # the merged room is matched by the larger of the two (the kitchen's 15.5 m^2 of its
    # 30.8, IoU 0.505); the corridor (15.2 m^2, IoU 0.495) is left unmatched
    assert by_name["kitchen"]["matched"] and not by_name["corridor"]["matched"]
    assert 0.5 < by_name["kitchen"]["iou"] < 0.51 and by_name["corridor"]["iou"] < 0.5
    assert by_name["kitchen"]["robot_room"] == by_name["corridor"]["robot_room"] == "room1"
    # the kitchen, entered, is judged by the merged room's belief: wrong, 18 of 86 m^2
    assert by_name["kitchen"]["believed"] == "corridor"
    assert score["category_accuracy"] == pytest.approx((86 - 18) / 86, abs=1e-4)


def test_a_corridor_split_in_two_counts_a_split() -> None:
    by_name = {t.name: t for t in OFFICE}
    halves = [TrueRoom("west", "corridor", (0.0, 2.5, 6.0, 4.0)),
              TrueRoom("east", "corridor", (6.0, 2.5, 12.0, 4.0))]
    cells = np.vstack([cells_in(by_name["corridor"].rect)])
    owner = ["room1" if x < 6.0 else "room2" for x, _ in cells]
    robot = RobotMap(cells, owner, RES * RES, {"room1": sure("corridor"),
                                                "room2": sure("office")})
    score = score_map(OFFICE[:1], robot, PATH)
    assert score["splits"] == 1 and score["merges"] == 0
    # scored against the two halves, the same map is perfect
    assert score_map(halves, robot, through((1.0, 3.2), (11.0, 3.2)))["splits"] == 0


def test_category_accuracy_weights_rooms_by_area_and_counts_only_rooms_entered() -> None:
    beliefs = {"room1": sure("corridor"), "room2": sure("kitchen"),
               "room3": sure("meeting_room"), "room4": sure("office")}
    robot = robot_map({"room1": ["corridor"], "room2": ["kitchen"], "room3": ["office1"],
                       "room4": ["office2"]}, beliefs)
    score = score_map(OFFICE, robot, PATH)  # the kitchen was seen, not entered
    assert score["entered_rooms"] == 3 and score["entered_area_m2"] == pytest.approx(68.0)
    # every room matched; of the rooms entered, the three entered
    assert (score["rooms_matched"], score["entered_matched"]) == (4, 3)
    # office1 (30 m^2) wrong; the corridor (18) and office2 (20) right
    assert score["category_accuracy"] == pytest.approx(38 / 68, abs=1e-4)
    # wrong in the small corridor instead: the accuracy is higher
    robot = robot_map({"room1": ["corridor"], "room2": ["kitchen"], "room3": ["office1"],
                       "room4": ["office2"]},
                      {**beliefs, "room1": sure("office"), "room3": sure("office")})
    assert score_map(OFFICE, robot, PATH)["category_accuracy"] == pytest.approx(50 / 68,
                                                                                abs=1e-4)


def test_a_room_seen_but_not_entered_or_owned_is_unmatched_and_no_room_entered_is_none(
) -> None:
    robot = robot_map({"room1": ["corridor"]}, {"room1": sure("corridor")},
                      unowned=("kitchen",))
    score = score_map(OFFICE, robot, through((6.0, 3.2), (6.5, 3.2)))
    kitchen = next(r for r in score["rooms"] if r["name"] == "kitchen")
    assert kitchen["robot_room"] is None and kitchen["mapped_m2"] > 10 and kitchen["iou"] == 0
    assert score["rooms_matched"] == 1 and score["merges"] == 0
    assert score_map(OFFICE, robot, [])["category_accuracy"] is None
    # standing in the kitchen doorway (within ENTER_DEPTH of its wall) is not entering it
    doorway = score_map(OFFICE, robot, through((2.0, 3.5), (2.0, 4.2)))
    assert not next(r for r in doorway["rooms"] if r["name"] == "kitchen")["entered"]


def test_an_episode_summary_carries_the_map_score(tmp_path: Path) -> None:
    """The Fig. 3a run of the active visual search paper (Göbelbecker et al.): the summary
    scores the rooms the robot mapped."""
    summary = run_episode({"target": "cerealbox", "world": "office", "seed": 1,
                           "output_dir": str(tmp_path)})
    score = summary["map_score"]
    assert json.loads((tmp_path / "summary.json").read_text())["map_score"] == score
    assert score["rooms_true"] == 4 and score["rooms_robot"] >= 1
    assert {r["name"] for r in score["rooms"]} == {"corridor", "kitchen", "office1",
                                                   "office2"}
    assert score["entered_rooms"] >= 1 and 0.0 <= score["category_accuracy"] <= 1.0
    corridor = next(r for r in score["rooms"] if r["name"] == "corridor")
    assert corridor["entered"] and corridor["robot_room"] is not None
    # the explanation's final beliefs name every robot room with its most probable
    # category, the same the score judged
    final = json.loads((tmp_path / "explanation.json").read_text())["final_beliefs"]["rooms"]
    assert len(final) == score["rooms_robot"]
    assert all(room["believed"] and room["p"] > 0 for room in final.values())
    for true_room in score["rooms"]:
        if true_room["robot_room"] is not None:
            assert final[true_room["robot_room"]]["believed"] == true_room["believed"]


def test_an_episode_summary_carries_what_its_placeholders_led_to(tmp_path: Path) -> None:
    """The summary and the trace's last `placeholders` belief agree on the placeholders the
    robot's own map resolved, per kind, with the model's mean prediction for them."""
    summary = run_episode({"target": "cerealbox", "world": "office", "seed": 1,
                           "output_dir": str(tmp_path)})
    placeholders = summary["placeholders"]
    assert json.loads((tmp_path / "summary.json").read_text())["placeholders"] == placeholders
    assert sum(kind["resolved"] for kind in placeholders.values()) > 0
    for kind in placeholders.values():
        assert 0 <= kind["new_room"] <= kind["resolved"] and 0.0 < kind["predicted"] < 1.0
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").read_text().splitlines()]
    traced = [e["placeholders"] for e in events if e["type"] == "belief" and "placeholders" in e]
    assert traced and traced[-1] == placeholders


def test_the_looks_claims_about_each_instance_are_scored_against_what_the_camera_saw() -> None:
    """Each true instance of the target: the robot room holding it, what the ledger says
    the looks there would have seen (the room, and the spaces of known objects beside it),
    whether a frame ever detected it and whether it was reported."""
    from types import SimpleNamespace

    from avs_planner.harness.scoring import evidence_score
    from conceptual_map.conceptual.existence import RelatedSpace

    remaining = {("room1", "cup"): 0.25, (RelatedSpace("on", "object1"), "cup"): 0.1,
                 (RelatedSpace("on", "object2"), "cup"): 0.5}
    ledger = SimpleNamespace(remaining=lambda loc, label: remaining.get((loc, label), 1.0))
    graph = SimpleNamespace(has_room=lambda rid: rid == "room1")
    objects = {"object1": SimpleNamespace(id="object1", label="table", position=(1.0, 1.0, 0.4)),
               "object2": SimpleNamespace(id="object2", label="shelf", position=(5.0, 5.0, 0.4)),
               "object3": SimpleNamespace(id="object3", label="cup", position=(1.1, 1.0, 0.8))}
    mind = SimpleNamespace(cmap=SimpleNamespace(objects=ledger, graph=graph), objects=objects)
    scored = evidence_score([("cup1", (1.2, 1.1, 0.8), "room1"), ("cup2", (3.0, 2.0, 0.9), "room1"),
                             ("cup3", (8.0, 8.0, 0.9), None)], mind, "cup",
                            detected={"cup1", "cup2"}, reported={"cup1"})
    assert scored == [
        # on the table the ledger says searched 90%; the cup beside it (a known cup) is not
        # a support
        {"name": "cup1", "room": "room1", "claimed_room": 0.75, "claimed_support": 0.9,
         "detected": True, "reported": True},
        {"name": "cup2", "room": "room1", "claimed_room": 0.75, "claimed_support": 0.0,
         "detected": True, "reported": False},
        # in no room the robot mapped: nothing claimed
        {"name": "cup3", "room": None, "claimed_room": 0.0, "claimed_support": 0.0,
         "detected": False, "reported": False},
    ]


def test_an_episode_summary_scores_the_looks_at_the_targets_instances(tmp_path: Path) -> None:
    """Fig. 3a: the cereal box the robot reports was detected, and what the looks claim of
    its room and its table is a probability; the summary file carries the same. (How a
    search of the table is credited there: the test above.)"""
    summary = run_episode({"target": "cerealbox", "world": "office", "seed": 1,
                           "output_dir": str(tmp_path)})
    evidence = summary["target_evidence"]
    assert json.loads((tmp_path / "summary.json").read_text())["target_evidence"] == evidence
    assert evidence and all(0.0 <= e["claimed_room"] <= 1.0 for e in evidence)
    assert summary["outcome"] == "found"
    reported = [e for e in evidence if e["reported"]]
    assert len(reported) == 1 and reported[0]["detected"]
    assert all(0.0 <= e["claimed_support"] <= 1.0 for e in evidence)
    matched = {r["robot_room"] for r in summary["map_score"]["rooms"]}
    assert all(e["room"] is None or e["room"] in matched for e in evidence)
