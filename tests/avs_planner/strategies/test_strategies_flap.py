"""The flap strategy (FLAP, Gedicke et al.) searches `flap_two_rooms` with depth frames in the 3D
map."""

import json

import pytest

from avs_planner.cli import main as avs_main
from avs_planner.harness import run_episode
from avs_planner.strategies import StrategyError, get_strategy

# small cycles keep the tests quick; the experiment uses the defaults (200 views, 50 clusters)
# no wall-clock limit on the planner: its node limit keeps the episodes the same under any load
QUICK = {"views": 60, "clusters": 20, "time_limit_s": 0.0, "prior_map": False}


def _flap_events(events):
    return [e for e in events if e["type"] == "flap"]


def test_flap_is_registered_with_its_options():
    strategy = get_strategy("flap")
    options = strategy.check_options({"greedy": "true", "views": "50"})
    assert options["greedy"] is True and options["views"] == 50
    assert strategy.load_prepare() is not None


def test_avs_simulate_flap_finds_a_cup_in_flap_two_rooms(tmp_path, capsys):
    """`avs simulate --strategy flap --pre-explore`: the survey (before the clock) registers
    the tables; the FLAP views over their tops find a cup, confirmed by a second frame."""
    out = tmp_path / "episode"
    code = avs_main(["simulate", "--world", "flap_two_rooms", "--target", "cup",
                     "--strategy", "flap", "--pre-explore", "--start", "2.5,3.6,1.57",
                     "--seed", "0", "--out", str(out), "--json",
                     *[f"--option={k}={v}" for k, v in QUICK.items()]])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0, summary["reason"]
    assert summary["outcome"] == "found" and summary["correct"]
    assert summary["strategy"] == "flap" and summary["views_processed"] > 0
    events = [json.loads(line) for line in (out / "trace.jsonl").read_text().splitlines()]
    flap = _flap_events(events)
    kinds = [e["event"] for e in flap]
    assert kinds[:2] == ["prepared", "region"]
    assert "decision" in kinds and kinds[-1] == "view" and flap[-1]["found"]
    decision = next(e for e in flap if e["event"] == "decision")
    assert decision["status"] == "go" and decision["candidates"] > 0
    assert {"sampling", "transitions", "planning", "total"} <= set(decision["seconds"])


def test_flap_gives_up_on_an_absent_label_through_the_omega_test():
    """No stapler in the world: the views reveal the support tops until p(V̂(S)) < omega
    (a high omega keeps the test short). The depth frames build and grow the 3D map."""
    events = []
    summary = run_episode({"target": "stapler", "world": "flap_two_rooms", "seed": 1,
                           "start": [2.5, 3.6, 1.57], "strategy": "flap", "pre_explore": True,
                           "strategy_options": {**QUICK, "omega": 0.35}}, events.append)
    assert summary["outcome"] == "gave_up", summary["reason"]
    assert "omega" in summary["reason"] and summary["object"] is None
    flap = _flap_events(events)
    assert flap[0]["event"] == "prepared" and flap[0]["voxels"] == 0  # no prior 3D map
    decisions = [e for e in flap if e["event"] == "decision"]
    assert decisions[-1]["status"] == "done" and decisions[-1]["p_remaining"] < 0.35
    assert all(d["p_remaining"] >= 0.35 for d in decisions[:-1])
    views = [e for e in flap if e["event"] == "view"]
    assert views and sum(v["p_seen"] for v in views) > 0
    known = [v["known_voxels"] for v in views]
    assert known[0] > 0 and all(b >= a for a, b in zip(known, known[1:], strict=False))
    assert known[-1] > known[0]
    survival = [v["survival"] for v in views]
    assert all(b <= a + 1e-9 for a, b in zip(survival, survival[1:], strict=False))


def test_the_task_can_give_the_region():
    """Option `volumes` (the FLAP paper's tasks give the volumes): checked with the other options,
    errors naming the entry."""
    flap = get_strategy("flap")
    given = [{"lo": [1, 2, 0.7], "hi": [2, 3, 1.0], "p": 0.3, "name": "t"}, {"lo": [0, 0, 0],
                                                                          "hi": [1, 1, 1]}]
    assert flap.check_options({"volumes": given})["volumes"] == given
    for bad, message in (
            ("box", r"option 'volumes' must be a list"),
            ([{"lo": [0, 0, 0]}], r"entry 0: need a mapping with lo and hi"),
            ([{"lo": [0, 0, 0], "hi": [1, 1, 1], "P": 0.2}], r"entry 0: unknown key\(s\) P"),
            ([{"lo": [0, 0, 1], "hi": [1, 1, 0]}], r"entry 0: .*need lo <= hi"),
            ([{"lo": [0, 0, 0], "hi": [1, 1, 1], "p": 1.5}], r"entry 0: .*probability")):
        with pytest.raises(StrategyError, match=message):
            flap.check_options({"volumes": bad})


def test_a_given_region_is_searched_to_the_omega_test_with_quiet_drives():
    """The FLAP paper's experiment: the six volumes of `flap_two_rooms`, `sense_en_route: false`
    (transitions are driving, turning, torso, head and sensing only: no place classification
    or watch on the way), one region, ended by omega."""
    from bench.flap_experiment import seed_volumes

    events = []
    volumes = seed_volumes()
    summary = run_episode({"target": "stapler", "world": "flap_two_rooms", "seed": 2,
                           "start": [2.5, 3.6, 1.57], "strategy": "flap", "pre_explore": True,
                           "strategy_options": {**QUICK, "omega": 0.4, "volumes": volumes,
                                                "sense_en_route": False,
                                                "survey_on": False}}, events.append)
    assert summary["outcome"] == "gave_up" and "given region" in summary["reason"]
    region = next(e for e in events if e.get("event") == "region")
    assert [v["name"] for v in region["volumes"]] == [v["name"] for v in volumes]
    assert region["p_total"] == pytest.approx(1 - 0.8 ** 6, abs=1e-3)
    started = region["t"]
    during = [e for e in events if e["t"] > started]
    assert not [e for e in during if e["type"] == "observation" and e.get("watching")]
    assert [e for e in during if e.get("event") == "view"]


def test_a_target_the_watch_confirmed_on_the_way_ends_the_survey():
    """A target the executor's watch confirmed while driving is a known object: the next
    survey stop reports it without looking (flap's own look skips detections near known
    objects, so it used to search on and give up with the target known)."""
    from types import SimpleNamespace

    from avs_planner.episode.mind import KnownObject
    from avs_planner.strategies.flap import _survey_stop

    cup = KnownObject("object7", "cup", (1.0, 2.0, 0.8), "room_a")
    ctx = SimpleNamespace(robot=None, options={"survey_headings": 6}, target="cup",
                          category=None, mind=SimpleNamespace(objects={cup.id: cup}))
    assert _survey_stop(ctx, depth=True, find=True, columns=32, tilts=(0.0,)) is cup
