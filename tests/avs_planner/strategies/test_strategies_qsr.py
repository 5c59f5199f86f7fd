"""The strategies of the QSR paper (Kunze et al.) search the desk world: survey, view selection,
monitor, learning, and the task's QSR descriptions."""

import json
import math

import numpy as np
import pytest

from avs_planner.episode import EpisodeError
from avs_planner.harness import run_episode
from avs_planner.harness.runner import EpisodeSpec
from avs_planner.qsr import LandmarkTracker, open_side
from avs_planner.strategies import get_strategy
from conceptual_map.metric import OccupancyGrid
from conceptual_map.qsr import load_qsr


def _spec(strategy, **extra):
    options = {"learn": False, **extra.pop("options", {})}
    return {"target": "cup", "world": "qsr_desks", "strategy": strategy, "seed": 1,
            "strategy_options": options, **extra}


@pytest.mark.parametrize("strategy", ["qsr", "supporting-planes", "random"])
def test_each_method_finds_a_cup_on_the_desks_and_counts_its_views(strategy, tmp_path):
    summary = run_episode(_spec(strategy, output_dir=str(tmp_path)))
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]
    assert summary["strategy"] == strategy and summary["plans"] == 0
    details = summary["details"]
    assert details["method"] == strategy and details["poses"] >= 1
    assert 0 < details["search_time_s"] <= 120.0 < summary["sim_time_s"] + 120.0
    assert {lm["label"] for lm in details["landmarks"]} >= {"monitor", "keyboard", "desk"}
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").read_text().splitlines()]
    looks = [e for e in events if e["type"] == "observation" and e["label"] == "cup"]
    assert summary["views_processed"] == len(looks) > 0
    poses = [e for e in events if e["type"] == "action"
             and e["action"] == f"(view-pose {strategy})" and e["status"] == "done"]
    assert len(poses) == details["poses"]
    assert events[-1]["type"] == "done" and events[-1]["outcome"] == "found"


def test_the_search_monitor_gives_up_on_an_absent_object():
    """Staplers have QSR descriptions but none is in the room: the monitor aborts the search
    after `abort_s` simulated seconds of search (the QSR paper's 120 s, shortened here)."""
    assert get_strategy("qsr").options["abort_s"] == 120.0
    summary = run_episode({**_spec("qsr", options={"abort_s": 30.0}), "target": "stapler"})
    assert summary["outcome"] == "gave_up" and summary["object"] is None
    assert summary["reason"].startswith("search monitor")
    assert summary["details"]["search_time_s"] >= 30.0
    assert summary["views_processed"] >= summary["details"]["poses"] >= 1


def test_a_found_cup_teaches_the_experience_store_the_next_search_reads(tmp_path):
    """The one episode test of the experience store: a QSR search that finds its cup adds
    what it learned (QSR counts, and the rooms it searched) to the store; the next episode
    on the store starts from it; one without a store starts from the default knowledge."""
    from conceptual_map.knowledge.experience import ExperienceStore

    store = tmp_path / "experience.sqlite"
    before = {d.key: d.count for d in load_qsr().descriptions_for("cup")}
    summary = run_episode(_spec("qsr", options={"learn": True}, experience=str(store),
                                building="desks-1"))
    assert summary["outcome"] == "found" and summary["details"]["knowledge"] == "experience"
    assert summary["experience"] == {"store": "experience.sqlite", "building": "desks-1",
                                     "updated": True}
    with ExperienceStore(store, create=False) as kept:
        learnt = {d.key: d.count for d in kept.qsr_for(load_qsr()).descriptions_for("cup")}
        scopes = kept.export()["scopes"]
    gained = {k: learnt[k] - before.get(k, 0.0) for k in learnt if learnt[k] != before.get(k)}
    assert gained and all(v == 1.0 for v in gained.values())
    assert scopes["all"]["episodes"] == scopes["building:desks-1"]["episodes"] == 1
    assert scopes["all"]["qsr"] == scopes["building:desks-1"]["qsr"]
    short = {"survey_stops": 0, "abort_s": 1.0}
    # the next search on the store starts from what was learnt, and adds its own episode
    again = run_episode(_spec("qsr", options={"learn": True, **short}, experience=str(store),
                              building="desks-1"))
    assert again["details"]["knowledge"] == "experience" and again["experience"]["updated"]
    with ExperienceStore(store, create=False) as kept:
        assert kept.export()["scopes"]["all"]["episodes"] == 2
    # one that names none starts from the default knowledge: nothing is kept in the process
    # (a service worker or a campaign process runs many episodes in any order)
    fresh = run_episode(_spec("qsr", options={"learn": True, **short}))
    assert fresh["details"]["knowledge"] == "default" and "experience" not in fresh


def test_task_descriptions_are_validated_with_clear_errors():
    good = [{"target": "cup", "relations": ["left", "close"], "of": "keyboard", "count": 2}]
    spec = EpisodeSpec.from_dict(_spec("qsr", qsr=good))
    assert [d.text() for d in spec.qsr.descriptions] == [
        "left(cup, keyboard) & close(cup, keyboard)"]
    assert EpisodeSpec.from_dict(_spec("qsr", qsr={"descriptions": good})).qsr is not None
    assert EpisodeSpec.from_dict(_spec("qsr")).qsr is None
    bad = [
        ([{"target": "cup", "relations": ["left"], "of": "sofa", "count": 1}],
         "descriptions[0].of: unknown landmark label 'sofa'"),
        ([{"target": "cup", "relations": ["above"], "of": "desk", "count": 1}],
         "unknown relation 'above'"),
        ([{"target": "cup", "relations": ["left"], "of": "desk"}], "descriptions[0]"),
        ("cup left of keyboard", "'qsr' must be a non-empty list"),
        ([], "'qsr' must be a non-empty list"),
    ]
    for data, message in bad:
        with pytest.raises(EpisodeError, match="qsr") as info:
            EpisodeSpec.from_dict(_spec("qsr", qsr=data))
        assert message in str(info.value)


def test_landmarks_need_two_sightings_and_face_the_open_side():
    tracker = LandmarkTracker(("monitor", "desk"), 0.25, 0.6)
    tracker.add("monitor", (2.0, 5.7, 0.9), (2.0, 3.0))
    tracker.add("monitor", (2.05, 5.68, 0.92), (2.5, 3.0))
    tracker.add("monitor", (4.0, 3.0, 0.9), (2.0, 3.0))  # a phantom, seen once
    tracker.add("desk", (2.0, 5.5, 0.4), (2.0, 3.0))
    tracker.add("desk", (2.4, 5.4, 0.4), (2.0, 3.0))  # the same desk, its centre seen apart
    confirmed = tracker.confirmed()
    assert sorted(c.label for c in confirmed) == ["desk", "monitor"]
    monitor = next(c for c in confirmed if c.label == "monitor")
    np.testing.assert_allclose(monitor.position, (2.025, 5.69, 0.91))
    # a room free below y = 5 and walled above: a landmark at the wall faces -y
    grid = OccupancyGrid((0.0, 0.0), (6.0, 6.0), 0.05)
    grid.logodds[...] = grid.model.clamp_min
    grid.logodds[:, 100:] = grid.model.clamp_max
    grid._touch()
    facing = open_side(grid, np.array([3.0, 5.5]), 0.3)
    assert facing == pytest.approx(-math.pi / 2, abs=math.radians(3))


def test_simulate_qsr_file_errors_exit_1_before_the_run(tmp_path, capsys):
    from avs_planner.cli import main

    bad = tmp_path / "bad.yaml"
    bad.write_text("- {target: cup, relations: [left, close], of: sofa, count: 1}\n")
    base = ["simulate", "--world", "qsr_desks", "--target", "cup", "--strategy", "qsr",
            "--out", str(tmp_path / "out")]
    assert main([*base, "--qsr", str(bad)]) == 1
    assert "qsr: descriptions[0].of: unknown landmark label 'sofa'" in capsys.readouterr().err
    assert main([*base, "--qsr", str(tmp_path / "missing.yaml")]) == 1
    assert "cannot read" in capsys.readouterr().err
    assert not (tmp_path / "out" / "summary.json").exists()


def test_pose_utility_option_is_checked():
    from avs_planner.strategies.registry import StrategyError

    for name in ("qsr", "supporting-planes", "random"):
        options = get_strategy(name).check_options({"utility": "eq2", "rerank": "false"})
        assert options["utility"] == "eq2" and options["rerank"] is False
        assert get_strategy(name).options["utility"] == "rate"
        with pytest.raises(StrategyError, match="'utility' must be one of rate, eq2"):
            get_strategy(name).check_options({"utility": "fastest"})


def _search_with_one_miss(relook: bool):
    """A qsr search on the desks whose camera misses the cup once, on the first frame of the
    first look (forced here); the summary, the trace and the robot's pose at every cup frame."""
    from avs_planner.harness.runner import Episode

    episode = Episode(EpisodeSpec.from_dict(_spec("qsr", options={"relook": relook})))
    robot, detect, asked = episode.robot, episode.robot.detect, []

    def missing_once(labels):
        seen = detect(labels)
        if "cup" in labels:
            asked.append(robot.pose)
            if len(asked) == 1:
                return []
        return seen

    robot.detect = missing_once
    events: list[dict] = []
    episode.trace.subscribe(events.append)
    return episode.run(), events, asked


def _looks(events):
    return [e for e in events if e["type"] == "action" and e["action"] == "(look)"]


def test_after_a_missed_look_the_robot_looks_again_from_the_same_pose():
    """The cup is in the best frustum of the first pose and the camera misses it once: the
    belief there drops by `seen_weight`, but staying for another look costs only sensing
    time while any other pose costs driving, so by the same score per second the robot looks
    again from where it stands (its best frustum may be the one just used) and finds the cup
    without a second pose."""
    summary, events, asked = _search_with_one_miss(relook=True)
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]
    starts = [e for e in events if e["type"] == "action" and e["action"] == "(view-pose qsr)"
              and e["status"] == "start"]
    assert summary["details"]["poses"] == 1 and len(starts) == 1
    assert [e["again"] for e in _looks(events)[:2]] == [False, True]
    assert np.allclose(asked[0], asked[-1])  # every cup frame from the same pose
    stay = next(e for e in events if e["type"] == "belief" and "stay_rate" in e)
    assert stay["stay_rate"] >= stay["move_rate"] > 0.0


@pytest.mark.slow
def test_without_relook_the_second_look_is_the_next_unused_frustum():
    summary, events, _ = _search_with_one_miss(relook=False)
    looks = _looks(events)
    assert not any(e["again"] for e in looks)
    assert not any("stay_rate" in e for e in events if e["type"] == "belief")
    assert (looks[0]["pan"], looks[0]["tilt"]) != (looks[1]["pan"], looks[1]["tilt"])
