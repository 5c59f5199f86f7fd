"""Campaign files: each kind of mistake is refused naming its entry; expansion is the product."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from avs_planner.experiment import CampaignError, load_campaign
from avs_planner.experiment import subjects as subjects_module
from avs_planner.experiment.campaign import (
    CAMPAIGN_DIR,
    HELDOUT_FIG3_NOISE_SEEDS,
    HELDOUT_WORLD_SEEDS_FROM,
    parse_campaign,
)
from avs_planner.experiment.report import PAPER_OUTCOME

STRATEGIES = ["switching", "exhaustive", "most-likely-room"]  # registered in main


def parse(data, base: Path = Path(".")):
    return parse_campaign(data, "c.yaml", base)


def refused(data, *fragments: str) -> str:
    with pytest.raises(CampaignError) as info:
        parse(data).runs()
    message = str(info.value)
    assert message.startswith("c.yaml: "), message
    for fragment in fragments:
        assert fragment in message, message
    return message


WORLD = {"worlds": ["office"], "targets": ["cerealbox"]}


@pytest.mark.parametrize(("data", "fragments"), [
    ([1, 2], ["a campaign is a mapping"]),
    ({**WORLD, "seed": 3}, ["unknown keys ['seed']"]),
    ({"targets": ["cup"]}, ["either 'worlds'"]),
    ({**WORLD, "scenarios": ["a"]}, ["either 'worlds'"]),
    ({"scenarios": ["a"], "targets": ["cup"]}, ["targets: scenarios bring their own"]),
    ({"scenarios": ["a", "zz"]}, ["scenarios[1]: ", "unknown scenario 'zz'"]),
    ({"worlds": ["office", "atlantis"], "targets": ["cup"]}, ["worlds[1]: "]),
    ({"worlds": [{"world": "office", "color": 1}], "targets": ["cup"]},
     ["worlds[0]: unknown keys ['color']"]),
    ({"worlds": [3], "targets": ["cup"]}, ["worlds[0]: a world name or path"]),
    ({"worlds": [{"world": "office", "start": [1, "x", 0]}], "targets": ["cup"]},
     ["worlds[0].start: a start pose is [x, y, yaw]"]),
    ({"worlds": [{"world": "office", "start_room": "attic"}], "targets": ["cup"]},
     ["worlds[0]: --start-room 'attic': the world has rooms"]),
    ({**WORLD, "strategies": ["switching", "teleport"]},
     ["strategies[1]: unknown strategy 'teleport'", "known strategies: ", "switching"]),
    ({**WORLD, "strategies": [{"name": "exhaustive", "options": {"headings": "many"}}]},
     ["strategies[0].options: strategy 'exhaustive': option 'headings' must be an int"]),
    ({**WORLD, "strategies": [{"name": "exhaustive", "options": {"speed": 2}}]},
     ["strategies[0].options: strategy 'exhaustive': unknown option(s) speed"]),
    ({**WORLD, "strategies": ["switching", "switching"]},
     ["strategies[1]: label 'switching' is used twice"]),
    ({**WORLD, "strategies": [{"name": "switching", "options": [1]}]},
     ["strategies[0].options: "]),
    ({**WORLD, "seeds": "5-2"}, ["seeds: range '5-2' is empty"]),
    ({**WORLD, "seeds": "0-3,x"}, ["seeds: 'x' is not a seed"]),
    ({**WORLD, "seeds": [1, "a"]}, ["seeds[1]: a seed is an integer"]),
    ({**WORLD, "seeds": "0-3,2"}, ["seeds: seed(s) [2] listed twice"]),
    ({**WORLD, "time_budget_s": -5}, ["time_budget_s: must be a positive"]),
    ({**WORLD, "wall_budget_s": "long"}, ["wall_budget_s: must be a number"]),
    ({**WORLD, "robots": ["pioneer", "r2d2"]}, ["robots[1]: unknown robot 'r2d2'", "pr2"]),
    ({"worlds": ["office"]}, ["worlds[0]: no targets"]),
    ({"worlds": ["office", "office_no_tables"], "targets": {"office": ["cup"]}},
     ["targets: no targets for world 'office_no_tables'"]),
    ({"worlds": ["office"], "targets": "auto"}, ["targets: 'auto' targets are for generated"]),
    ({"worlds": ["office"], "targets": [{"label": "cup", "expected": "maybe"}]},
     ["targets[0].expected: found or gave_up"]),
    ({"worlds": ["office"], "targets": [["cup"]]}, ["targets[0]: a label or"]),
    ({"worlds": ["office"], "targets": ["cup", "banana"]},
     ["targets[1]: unknown target label 'banana'; the knowledge knows book, cerealbox"]),
    ({"worlds": ["office"], "targets": {"office": [{"label": "bananas"}]}},
     ["targets.office[0].label: unknown target label 'bananas'"]),
    ({"worlds": [{"generate": {"style": "office"}}], "targets": "auto"},
     ["worlds[0].generate: a mapping with 'seeds'"]),
    ({"worlds": [{"generate": {"seeds": "0-2", "rooms": 0}}], "targets": "auto"},
     ["worlds[0].generate.rooms: a positive number"]),
    ({"worlds": ["office", "office"], "targets": ["cup"]}, ["share the id 'office-cup"]),
])
def test_a_bad_campaign_is_refused_naming_the_entry(data, fragments):
    refused(data, *fragments)


def test_an_unknown_built_in_lists_the_built_ins():
    with pytest.raises(CampaignError, match="built-in campaigns are .*seed003-fig3"):
        load_campaign("seed004-fig9")


def test_a_broken_yaml_file_is_named(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("worlds: [office\n", encoding="utf-8")
    with pytest.raises(CampaignError, match=r"broken\.yaml: cannot read campaign"):
        load_campaign(path)


def test_worlds_targets_strategies_robots_and_seeds_multiply():
    campaign = parse({"worlds": ["office", "office_no_tables"],
                      "targets": ["cerealbox", {"label": "stapler", "expected": "found"}],
                      "strategies": ["switching", {"name": "exhaustive", "label": "ex-fast",
                                                   "options": {"headings": 8}}],
                      "robots": ["pioneer", "pr2"], "seeds": "0-2", "time_budget_s": 300})
    runs = campaign.runs()
    assert len(runs) == 2 * 2 * 2 * 2 * 3
    assert len({r.run_id for r in runs}) == len(runs)
    first = runs[0]
    assert first.run_id == "office-cerealbox-switching-pioneer-s0"
    assert dict(first.episode) == {"world": "office", "target": "cerealbox", "seed": 0,
                                   "robot": "pioneer", "time_budget_s": 300.0}
    ex = next(r for r in runs if r.strategy.label == "ex-fast")
    assert ex.episode["strategy"] == "exhaustive"
    assert ex.episode["strategy_options"] == {"headings": 8}
    expected = {(r.subject.world, r.subject.target): r.subject.expected for r in runs}
    assert expected[("office", "cerealbox")] == "found"  # on the kitchen table
    assert expected[("office_no_tables", "cerealbox")] == "gave_up"  # Fig. 3e: none anywhere
    assert expected[("office_no_tables", "stapler")] == "found"  # as the entry says


def test_targets_per_world_and_world_files_relative_to_the_campaign(tmp_path):
    world = Path(subjects_module.__file__).parents[2] / "sim" / "worlds" / "office.yaml"
    (tmp_path / "mine.yaml").write_text(world.read_text(encoding="utf-8"), encoding="utf-8")
    campaign = parse({"worlds": ["office", {"world": "mine.yaml", "targets": ["cup"],
                                            "start_room": "kitchen"}],
                      "targets": {"office": ["stapler", "toilet"]}}, tmp_path)
    runs = campaign.runs()
    assert [(r.subject.world, r.subject.target, r.subject.expected) for r in runs] == [
        ("office", "stapler", "found"), ("office", "toilet", "gave_up"),
        ("mine", "cup", "found")]  # office.yaml has a cup
    assert runs[2].episode["world"] == str(tmp_path / "mine.yaml")
    assert runs[2].episode["start_room"] == "kitchen"


def test_generated_worlds_with_auto_targets(monkeypatch):
    calls = []

    def fake(seed, style, rooms):
        calls.append((seed, style, rooms))
        return [("cup", True), (f"thing{seed}", True), ("banana", False)]

    monkeypatch.setattr(subjects_module, "generated_targets", fake)
    campaign = parse({"worlds": [{"generate": {"seeds": "3-6", "style": "office", "rooms": 6}}],
                      "targets": "auto", "strategies": STRATEGIES})
    runs = campaign.runs()
    assert calls == [(s, "office", 6) for s in range(3, 7)]
    assert len(runs) == 4 * 3 * 3
    run = runs[0]
    assert run.run_id == "gen-office-3-r6-cup-switching-s0"
    assert run.episode["generate"] == {"seed": 3, "style": "office", "rooms": 6}
    assert "world" not in run.episode
    assert run.subject.group == "gen-office-r6"
    in_4 = {(r.subject.target, r.subject.expected) for r in runs
            if r.subject.world == "gen-office-4-r6"}
    assert in_4 == {("cup", "found"), ("thing4", "found"), ("banana", "gave_up")}


def test_the_built_in_seed003_campaign_is_fig3_a_to_f_times_20_seeds():
    campaign = load_campaign("seed003-fig3")
    runs = campaign.runs()
    assert len(runs) == 120
    assert {r.subject.scenario: r.subject.expected for r in runs} == PAPER_OUTCOME
    assert sorted({r.seed for r in runs}) == list(range(20))
    f = next(r for r in runs if r.subject.scenario == "f")
    assert f.episode["pre_explore"] is True and f.episode["target"] == "whiteboardmarker"


def test_generated_worlds_with_the_generators_own_targets():
    pytest.importorskip("sim.generate", reason="the world generator is not in this build")
    runs = parse({"worlds": [{"generate": {"seeds": "0-1", "style": "office", "rooms": 6}}],
                  "targets": "auto"}).runs()
    assert len(runs) == 2 * 3
    for world in ("gen-office-0-r6", "gen-office-1-r6"):
        expected = sorted(r.subject.expected for r in runs if r.subject.world == world)
        assert expected == ["found", "found", "gave_up"], world


def test_the_built_in_generated_campaign_is_50_worlds_times_3_strategies(monkeypatch):
    monkeypatch.setattr(subjects_module, "generated_targets",
                        lambda seed, style, rooms: [("cup", True), ("mug", True), ("x", False)])
    runs = load_campaign("generated-50").runs()
    assert len(runs) == 50 * 3 * 3
    assert {r.strategy.name for r in runs} == set(STRATEGIES)
    assert {r.subject.spec["generate"]["rooms"] for r in runs} == {6}


def test_the_held_out_campaign_is_unseen_buildings_of_three_styles_by_both_robots(
        monkeypatch):
    calls = []

    def fake(seed, style, rooms):
        calls.append((seed, style, rooms))
        return [("cup", True), ("book", True), ("stapler", False)]

    monkeypatch.setattr(subjects_module, "generated_targets", fake)
    runs = load_campaign("heldout").runs()
    assert len(runs) == 3 * 8 * 3 * 3 * 2
    assert sorted(calls) == sorted((seed, style, None) for style in ("office", "apartment",
                                                                     "lab")
                                   for seed in range(10000, 10008))
    assert {r.subject.group for r in runs} == {"gen-office", "gen-apartment", "gen-lab"}
    assert {r.robot for r in runs} == {"pioneer", "pr2"}
    assert [s.name for s in load_campaign("heldout").strategies] == STRATEGIES
    assert {r.seed for r in runs} == {100}
    assert all(r.episode["generate"]["seed"] >= HELDOUT_WORLD_SEEDS_FROM for r in runs)
    assert {r.subject.expected for r in runs} == {"found", "gave_up"}
    assert {r.episode["robot"] for r in runs} == {"pioneer", "pr2"}


def test_a_pr2_run_of_the_held_out_campaign_searches_the_world_generated_for_the_pr2():
    pytest.importorskip("sim.generate", reason="the world generator is not in this build")
    from avs_planner.harness.sim_robot import generated_spec
    from sim.generate import generate_world

    campaign = load_campaign("heldout")
    firsts = {}
    for run in campaign.runs():
        if run.robot == "pr2":
            firsts.setdefault(run.subject.group, run)
    assert len(firsts) == 3
    for run in firsts.values():
        gen = run.episode["generate"]
        ours = generated_spec(gen, run.episode["robot"])
        for_pr2 = generate_world(gen["seed"], gen["style"], gen["rooms"], robot="pr2").spec()
        assert ours == for_pr2, run.run_id


def test_the_held_out_fig3_campaign_is_a_to_f_over_the_held_out_noise_seeds():
    runs = load_campaign("heldout-fig3").runs()
    assert len(runs) == 6 * 20
    assert {r.subject.scenario: r.subject.expected for r in runs} == PAPER_OUTCOME
    assert sorted({r.seed for r in runs}) == list(HELDOUT_FIG3_NOISE_SEEDS)
    assert {r.strategy.name for r in runs} == {"switching"}


@pytest.mark.parametrize("name", ["seed003-fig3", "generated-50", "development"])
def test_development_campaigns_stay_off_the_held_out_seeds(name, monkeypatch):
    monkeypatch.setattr(subjects_module, "generated_targets",
                        lambda seed, style, rooms: [("cup", True)])
    for run in load_campaign(name).runs():
        assert run.episode.get("generate", {}).get("seed", 0) < HELDOUT_WORLD_SEEDS_FROM
        if run.subject.scenario:
            assert run.seed not in HELDOUT_FIG3_NOISE_SEEDS


def test_built_in_campaigns_name_papers_by_title_not_by_seed_number():
    for path in CAMPAIGN_DIR.glob("*.yaml"):
        text = path.read_text(encoding="utf-8").lower()
        assert "seed 003" not in text and "issue 34" not in text, path.name


# ---- tasks of several objects ------------------------------------------------------------


@pytest.mark.parametrize(("targets", "fragments"), [
    ([{"targets": ["cup", "cup"]}], ["targets[0]: 'targets' names cup more than once"]),
    ([{"targets": ["cup", "book"], "mode": "most"}],
     ["targets[0]: 'mode' must be one of all, any; got 'most'"]),
    (["cup", {"targets": ["cup", "banana"]}],
     ["targets[1].targets[1]: unknown target label 'banana'"]),
    ([{"targets": "cup"}], ["targets[0]: 'targets' must be a non-empty list"]),
    ([{"targets": ["cup", "book"], "count": "all"}],
     ["targets[0]: 'count: all' finds every instance of one label"]),
    ([{"label": "chair", "count": "all", "stop_below": 1.5}],
     ["targets[0]: 'stop_below' must be a probability"]),
    ([{"label": "chair", "stop_below": 0.2}],
     ["targets[0]: 'stop_below' applies to 'count: all' only"]),
    ([{"label": "chair", "count": "some"}], ["targets[0]: 'count' must be one of one, all"]),
    ([{"label": "chair", "targets": ["cup"], "count": "all"}],
     ["targets[0]: give 'label'", "or 'targets'"]),
    ([{"mode": "any"}], ["targets[0]: a task names its labels"]),
    ([{"targets": ["cup", "book"], "colour": "red"}], ["targets[0]: unknown keys ['colour']"]),
    ([{"targets": ["cup", "book"], "expected": "maybe"}],
     ["targets[0].expected: found or gave_up"]),
    ([{"targets": ["cup", "book"], "singles": "yes"}], ["targets[0].singles: true or false"]),
    ([{"label": "bananas", "count": "all"}], ["targets[0].label: unknown target label"]),
    ([{"auto": "present", "all": 3}], ["targets[0]: 'auto' targets are for generated worlds"]),
    (["cup", "auto"], ["targets[1]: 'auto' targets are for generated worlds"]),
])
def test_a_bad_task_is_refused_naming_its_position(targets, fragments):
    refused({"worlds": ["office"], "targets": targets}, *fragments)


def _labels_of(counts):
    return lambda seed, style, rooms: dict(counts)


BUILDING = {"cup": 3, "book": 1, "stapler": 2, "monitor": 1}


@pytest.mark.parametrize(("targets", "fragments"), [
    ({"auto": "absent", "all": 2}, ["targets.auto: 'present'"]),
    ({"auto": "present"}, ["targets: give one of 'all: N'"]),
    ({"auto": "present", "all": 2, "any": 2}, ["targets: give one of 'all: N'"]),
    ({"auto": "present", "all": 1}, ["targets.all: a number of labels from 2 to 8, got 1"]),
    ({"auto": "present", "any": True}, ["targets.any: a number of labels from 2 to 8"]),
    ({"auto": "present", "all": 5}, ["targets.all: world seed 7 (gen-office-7): all: 5 asks "
                                     "for 5 labels the building holds; it holds 4"]),
    ({"auto": "present", "count": "one"}, ["targets.count: 'all'"]),
    ({"auto": "present", "count": "all", "pick": 0}, ["targets.pick: a positive number"]),
    ({"auto": "present", "count": "all", "pick": 3},
     ["targets.pick: world seed 7 (gen-office-7): pick 3 asks for 3 labels with 2 or more "
      "instances; the building has 2"]),
    ({"auto": "present", "any": 2, "pick": 1}, ["targets.pick: 'pick' goes with 'count: all'"]),
    ({"auto": "present", "count": "all", "stop_below": 0}, ["targets: 'stop_below' must be"]),
    ({"auto": "present", "all": 2, "mode": "any"}, ["targets: unknown keys ['mode']"]),
    (["auto", {"auto": "present", "any": 9}], ["targets[1].any: a number of labels"]),
])
def test_a_bad_task_over_a_buildings_labels_is_refused(targets, fragments, monkeypatch):
    monkeypatch.setattr(subjects_module, "generated_instances", _labels_of(BUILDING))
    refused({"worlds": [{"generate": {"seeds": 7}}], "targets": targets}, *fragments)


def test_tasks_in_a_world_file_expect_what_the_world_holds():
    """office.yaml holds a cup and a cerealbox, no book and no toilet."""
    runs = parse({"worlds": ["office"], "targets": [
        "cup", {"targets": ["cup", "book"], "mode": "any", "singles": True},
        {"targets": ["cup", "book"]}, {"targets": ["toilet", "book"], "mode": "any"},
        {"label": "cup", "count": "all", "stop_below": 0.05},
        {"label": "toilet", "count": "all", "expected": "found"},
        {"targets": ["cerealbox"]}]}).runs()
    got = [(r.subject.target, r.subject.kind, r.subject.expected) for r in runs]
    assert got == [("cup", "", "found"), ("cup or book", "any", "found"),
                   ("book", "", "gave_up"),  # added by singles; cup is listed already
                   ("cup and book", "all", "gave_up"), ("toilet or book", "any", "gave_up"),
                   ("every cup (stop below 0.05)", "count", "found"),
                   ("every toilet", "count", "found"),  # as the entry says
                   ("cerealbox", "", "found")]  # a task of one label is one search
    assert [r.run_id for r in runs][1:6] == [
        "office-cup-or-book-switching-s0", "office-book-switching-s0",
        "office-cup-and-book-switching-s0", "office-toilet-or-book-switching-s0",
        "office-every-cup-stop-below-0.05-switching-s0"]


def test_a_task_subject_becomes_an_episode_spec_with_targets_mode_and_count():
    runs = parse({"worlds": ["office"], "targets": [
        {"targets": ["cup", "book"], "mode": "any"},
        {"label": "chair", "count": "all", "stop_below": 0.05}, {"label": "chair",
                                                                 "count": "all"}],
        "time_budget_s": 300}).runs()
    specs = [dict(r.episode) for r in runs]
    assert specs[0] == {"world": "office", "targets": ["cup", "book"], "mode": "any",
                        "count": "one", "seed": 0, "time_budget_s": 300.0}
    assert specs[1] == {"world": "office", "targets": ["chair"], "mode": "all", "count": "all",
                        "stop_below": 0.05, "seed": 0, "time_budget_s": 300.0}
    assert "stop_below" not in specs[2] and "target" not in specs[2]
    assert runs[0].columns() == {
        "run_id": "office-cup-or-book-switching-s0", "scenario": "", "world": "office",
        "group": "office", "target": "cup or book", "expected": "found",
        "strategy": "switching", "robot": "", "seed": 0, "task": "any",
        "task_labels": "cup book", "sequence": "", "task_index": None, "memory": "",
        "priors": ""}
    assert runs[1].columns()["task"] == "count"
    from avs_planner.harness.runner import EpisodeSpec

    for spec in specs:  # what the episode reads: the same task
        episode = EpisodeSpec.from_dict(spec)
        assert episode.task is not None and episode.target == spec["targets"][0]
    assert EpisodeSpec.from_dict(specs[0]).task.mode == "any"
    assert EpisodeSpec.from_dict(specs[1]).task.stop_below == 0.05


def test_tasks_over_a_buildings_labels_are_chosen_from_its_seed(monkeypatch):
    import random

    monkeypatch.setattr(subjects_module, "generated_instances", _labels_of(BUILDING))
    monkeypatch.setattr(subjects_module, "generated_targets",
                        lambda seed, style, rooms: [("cup", True), ("book", True),
                                                    ("keyboard", False)])
    targets = [{"auto": "present", "all": 3, "singles": True},
               {"auto": "present", "any": 2, "singles": True},
               {"auto": "present", "count": "all"}, "auto"]
    runs = parse({"worlds": [{"generate": {"seeds": "7-8", "style": "lab"}}],
                  "targets": targets}).runs()
    for seed in (7, 8):
        order = sorted(BUILDING)
        random.Random(seed).shuffle(order)
        mine = [r.subject for r in runs if r.subject.world == f"gen-lab-{seed}"]
        tasks = {s.kind: s for s in mine if s.task}
        assert list(tasks["all"].task["targets"]) == order[:3]
        assert list(tasks["any"].task["targets"]) == order[:2]  # two of the three
        counted = [s.labels[0] for s in mine if s.kind == "count"]
        assert counted == [x for x in order if BUILDING[x] >= 2]  # cup and stapler
        singles = [s.target for s in mine if not s.task]
        # the singles of the three labels, then the generator's own targets (cup and book
        # once each: a single search `singles` adds is left out when the list holds it)
        assert sorted(singles) == sorted(set(order[:3]) | {"cup", "book", "keyboard"})
        assert len(singles) == len(set(singles))
        assert {s.expected for s in mine if s.target != "keyboard"} == {"found"}
        assert all(s.spec["generate"] == {"seed": seed, "style": "lab", "rooms": None}
                   for s in mine)
    again = parse({"worlds": [{"generate": {"seeds": "7-8", "style": "lab"}}],
                   "targets": targets}).runs()
    assert [r.run_id for r in again] == [r.run_id for r in runs]  # deterministic


def test_count_tasks_pick_the_first_labels_with_several_instances(monkeypatch):
    monkeypatch.setattr(subjects_module, "generated_instances", _labels_of(BUILDING))
    runs = parse({"worlds": [{"generate": {"seeds": 7}}], "targets": {
        "auto": "present", "count": "all", "pick": 1, "stop_below": 0.2}}).runs()
    assert len(runs) == 1
    assert runs[0].subject.labels[0] in ("cup", "stapler")
    assert runs[0].episode["stop_below"] == 0.2 and runs[0].episode["count"] == "all"
    assert runs[0].subject.target.endswith("(stop below 0.2)")


def test_the_generators_instance_counts():
    pytest.importorskip("sim.generate", reason="the world generator is not in this build")
    from avs_planner.harness.worlds import generated_instances
    from sim.generate import generate_world

    counts = generated_instances(314, "office")
    world = generate_world(314, "office")
    assert sorted(counts) == world.labels_present()
    assert sum(counts.values()) == len(world.data["objects"])


def _no_generator(monkeypatch):
    monkeypatch.setattr(subjects_module, "generated_targets",
                        lambda seed, style, rooms: [("cup", True)])
    monkeypatch.setattr(subjects_module, "generated_instances",
                        lambda seed, style, rooms: {"cup": 3, "book": 2, "stapler": 2})


def test_the_task_benchmark_campaign_and_its_held_out_twin(monkeypatch):
    _no_generator(monkeypatch)
    dev, held = load_campaign("tasks-dev"), load_campaign("tasks-heldout")
    for campaign, seeds, noise in ((dev, range(314, 326), 0),
                                   (held, range(10000, 10008), 100)):
        runs = campaign.runs()
        worlds = {r.episode["generate"]["seed"] for r in runs}
        assert worlds == set(seeds)
        assert {r.seed for r in runs} == {noise}
        assert {r.strategy.name for r in runs} == {"switching"}
        assert {r.robot for r in runs} == {"pioneer"}
        kinds = [r.subject.kind for r in runs]
        per_world = 2 * len(seeds)  # office and lab
        assert kinds.count("all") == kinds.count("any") == kinds.count("count") == per_world
        assert kinds.count("") == 3 * per_world  # the single searches of the all task
    strip = {"name", "description", "seeds"}

    def body(name):
        data = yaml.safe_load((CAMPAIGN_DIR / f"{name}.yaml").read_text(encoding="utf-8"))
        for world in data["worlds"]:
            world["generate"].pop("seeds")
        return {k: v for k, v in data.items() if k not in strip}

    assert body("tasks-dev") == body("tasks-heldout")  # the same content, other seeds
    assert all(r.episode["generate"]["seed"] >= HELDOUT_WORLD_SEEDS_FROM for r in held.runs())
