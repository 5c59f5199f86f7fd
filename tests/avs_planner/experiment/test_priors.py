"""Campaigns with the experience store: `experience` and `priors` parsed with errors naming the
key, episodes given the store, the learned arm reading it without writing, the `priors`
column and the report's pairs; `generate.table` for worlds of the moved kind."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from avs_planner.episode import EpisodeError
from avs_planner.experiment import CampaignError
from avs_planner.experiment import subjects as subjects_module
from avs_planner.experiment.campaign import (
    CAMPAIGN_DIR,
    HELDOUT_WORLD_SEEDS_FROM,
    load_campaign,
    parse_campaign,
)
from avs_planner.experiment.report import render
from avs_planner.experiment.report_priors import priors_pairs, priors_ratios
from avs_planner.experiment.results import COLUMNS, read_results
from avs_planner.experiment.runner import RunOptions, run_campaign
from avs_planner.harness.runner import EpisodeSpec, run_episode
from avs_planner.harness.sim_robot import generated_spec
from avs_planner.harness.worlds import generated_instances, generated_name
from conceptual_map.knowledge.experience import Evidence, ExperienceError, ExperienceStore

FAKE = str(Path(__file__).with_name("fake_runner.py"))
WORLDS = {"worlds": ["office"], "targets": ["cerealbox"]}


def parse(data):
    return parse_campaign(data, "c.yaml", Path("."))


def refused(data, *fragments):
    with pytest.raises(CampaignError) as info:
        parse(data).runs()
    for fragment in fragments:
        assert fragment in str(info.value), str(info.value)


@pytest.mark.parametrize(("extra", "fragments"), [
    ({"experience": True}, ["c.yaml: experience: a mapping"]),
    ({"experience": {"learn": "yes"}}, ["experience.learn: true (episodes add"]),
    ({"experience": {}}, ["experience.learn:"]),
    ({"experience": {"learn": True, "keep": 1}}, ["experience: unknown keys ['keep']"]),
    ({"experience": {"learn": False}}, ["experience.store: learn: false reads a store"]),
    ({"experience": {"learn": True, "store": ""}}, ["experience.store: the path"]),
    ({"priors": ["default", "learned"]}, ["priors: the learned arm reads an experience"]),
    ({"priors": ["default", "learned"], "experience": {"learn": True}},
     ["experience.learn: false with 'priors'"]),
    ({"priors": ["default", "fancy"], "experience": {"store": "s", "learn": False}},
     ["priors[1]: unknown arm 'fancy'"]),
    ({"priors": ["learned", "learned"], "experience": {"store": "s", "learn": False}},
     ["priors[1]: arm 'learned' is listed twice"]),
    ({"priors": []}, ["priors: a non-empty list"]),
])
def test_bad_experience_and_priors_are_refused_naming_the_key(extra, fragments):
    refused({**WORLDS, **extra}, *fragments)


def test_experience_is_not_for_sequences():
    refused({"worlds": [{"generate": {"seeds": 1}}], "sequence": {"tasks": 2},
             "experience": {"learn": True}}, "c.yaml: experience: not with 'sequence'")


def test_training_gives_every_episode_the_store_and_its_building():
    runs = parse({**WORLDS, "experience": {"learn": True}}).runs()
    assert [r.episode["experience"] for r in runs] == ["experience.sqlite3"]
    assert runs[0].episode["building"] == "office" and "learn" not in runs[0].episode
    assert runs[0].priors == "" and runs[0].columns()["priors"] == ""


def test_the_priors_arms_pair_each_run_with_and_without_the_store():
    runs = parse({**WORLDS, "seeds": "0-1", "priors": ["default", "learned"],
                  "experience": {"store": "../train/experience.sqlite3",
                                 "learn": False}}).runs()
    assert [r.run_id for r in runs] == [
        f"office-cerealbox-switching-s{s}-priors-{arm}" for s in (0, 1)
        for arm in ("default", "learned")]
    default, learned = runs[0], runs[1]
    assert "experience" not in default.episode and "learn" not in default.episode
    assert learned.episode["experience"] == "../train/experience.sqlite3"
    assert (learned.episode["learn"], learned.episode["building"]) == (False, "office")
    assert {k: v for k, v in learned.episode.items()
            if k not in ("experience", "learn", "building")} == default.episode
    assert (default.priors, learned.columns()["priors"]) == ("default", "learned")


# ---- generated worlds of the moved kind ---------------------------------------------------


def test_a_generated_entry_takes_a_placement_table_naming_it_in_worlds_and_groups():
    runs = parse({"worlds": [{"generate": {"seeds": 401, "table": "moved"}}],
                  "targets": [{"auto": "present", "labels": 3}]}).runs()
    assert len(runs) == 3
    assert {r.subject.world for r in runs} == {"gen-office-401-moved"}
    assert {r.subject.group for r in runs} == {"gen-office-moved"}
    assert runs[0].episode["generate"] == {"seed": 401, "style": "office", "rooms": None,
                                           "table": "moved"}
    held = set(generated_instances(401, "office", table="moved"))
    assert {r.subject.target for r in runs} <= held
    assert {r.subject.expected for r in runs} == {"found"}
    plain = parse({"worlds": [{"generate": {"seeds": 401}}], "targets": ["cup"]}).runs()
    assert "table" not in plain[0].episode["generate"]  # default worlds' specs as before


def test_a_bad_table_is_refused_naming_generate_table():
    refused({"worlds": [{"generate": {"seeds": 1, "table": "tilted"}}], "targets": ["cup"]},
            "worlds[0].generate.table: a placement table, one of default, moved")
    with pytest.raises(EpisodeError, match="generate.table: expected a placement table"):
        generated_spec({"seed": 1, "table": "tilted"})
    with pytest.raises(EpisodeError, match="generate.table"):
        generated_spec({"seed": 1, "table": 3})


def test_the_harness_builds_moved_worlds_and_names_them():
    spec = generated_spec({"seed": 402, "style": "office", "table": "moved"})
    assert spec.name == "office_402_moved"
    assert generated_name(402, "office", None, "moved") == "gen-office-402-moved"
    assert generated_name(402, "office") == "gen-office-402"


@pytest.mark.parametrize(("item", "fragment"), [
    ({"auto": "present", "labels": 0}, "targets[0].labels: a positive number"),
    ({"auto": "present", "labels": 2, "singles": True}, "targets[0].singles: 'singles' does"),
    ({"auto": "present", "labels": 9}, "targets[0].labels: world seed 401"),
])
def test_bad_single_searches_over_a_buildings_labels_are_refused(item, fragment):
    refused({"worlds": [{"generate": {"seeds": 401, "table": "moved"}}], "targets": [item]},
            fragment)


def test_the_cli_offers_the_generators_tables():
    from avs_planner.cli.world import _TABLES
    from sim.generation.table import TABLES

    assert tuple(TABLES) == _TABLES


# ---- the built-in campaigns ---------------------------------------------------------------


def test_the_priors_campaigns_train_on_development_and_test_on_new_buildings(monkeypatch):
    monkeypatch.setattr(subjects_module, "generated_instances",
                        lambda seed, style, rooms, **table: {"cup": 2, "book": 1,
                                                             "stapler": 1, "monitor": 1})
    train, dev, held = (load_campaign(n) for n in ("priors-train", "priors-dev",
                                                   "priors-heldout"))
    seeds = {c.name: {r.episode["generate"]["seed"] for r in c.runs()}
             for c in (train, dev, held)}
    assert seeds["priors-train"] == set(range(400, 430))
    assert seeds["priors-dev"] == set(range(430, 450))
    assert seeds["priors-heldout"] == set(range(10200, 10220))
    assert all(s >= HELDOUT_WORLD_SEEDS_FROM for s in seeds["priors-heldout"])
    for campaign in (train, dev, held):
        runs = campaign.runs()
        assert {r.episode["generate"]["table"] for r in runs} == {"moved"}
        assert {r.strategy.name for r in runs} == {"switching"}
    assert len(train.runs()) == 90 and train.experience.learn
    assert {r.episode["experience"] for r in train.runs()} == {"experience.sqlite3"}
    for campaign in (dev, held):
        assert campaign.priors == ("default", "learned") and not campaign.experience.learn
        assert campaign.experience.store == "../priors-train/experience.sqlite3"
        assert len(campaign.runs()) == 120
    assert {r.seed for r in held.runs()} == {100}
    text = (CAMPAIGN_DIR / "priors-heldout.yaml").read_text(encoding="utf-8")
    assert "NOTHING may be tuned" in text


# ---- running: the store's place, the arms, the column -------------------------------------


def _fake(out: Path, data: dict, **options):
    campaign = parse_campaign({"name": "p", **data}, "p.yaml", Path("."))
    return run_campaign(campaign, RunOptions(out, workers=2,
                                             episode_runner=f"{FAKE}:summary", **options))


def test_training_makes_the_store_in_the_output_directory_before_any_episode(tmp_path):
    out = tmp_path / "train"
    _fake(out, {"scenarios": ["a"], "seeds": "0-1", "experience": {"learn": True}})
    store = out / "experience.sqlite3"
    ExperienceStore(store, readonly=True).close()  # made, and a store
    record = json.loads((out / "runs" / "a-switching-s0" / "record.json").read_text())
    assert record["spec"]["experience"] == str(store.resolve())
    assert record["spec"]["building"] == "office"


def test_the_learned_arm_needs_its_store_and_reads_it_where_the_campaign_says(tmp_path):
    data = {"scenarios": ["a"], "seeds": "0-1", "priors": ["default", "learned"],
            "experience": {"store": "../train/experience.sqlite3", "learn": False}}
    with pytest.raises(CampaignError, match="no experience store there.*training campaign"):
        _fake(tmp_path / "test", data)
    (tmp_path / "train").mkdir()
    ExperienceStore(tmp_path / "train" / "experience.sqlite3").close()
    result = _fake(tmp_path / "test", data)
    rows = read_results(result.results)
    assert "priors" in COLUMNS
    assert [(r["run_id"], r["priors"]) for r in rows] == [
        ("a-switching-s0-priors-default", "default"), ("a-switching-s0-priors-learned",
                                                       "learned"),
        ("a-switching-s1-priors-default", "default"), ("a-switching-s1-priors-learned",
                                                       "learned")]
    record = json.loads((tmp_path / "test" / "runs" / "a-switching-s0-priors-learned"
                         / "record.json").read_text())
    assert record["spec"]["experience"] == str(
        (tmp_path / "train" / "experience.sqlite3").resolve())
    other = tmp_path / "elsewhere.sqlite3"
    ExperienceStore(other).close()
    _fake(tmp_path / "test2", data, experience=other)
    record = json.loads((tmp_path / "test2" / "runs" / "a-switching-s0-priors-learned"
                         / "record.json").read_text())
    assert record["spec"]["experience"] == str(other.resolve())


def test_the_report_pairs_the_arms():
    def row(world, arm, time, success=True):
        return {"run_id": f"{world}-{arm}", "scenario": "", "world": world, "group": "g",
                "target": "cup", "expected": "found", "strategy": "switching",
                "robot": "pioneer", "seed": 1, "priors": arm, "status": "ok",
                "outcome": "found" if success else "timeout", "success": success,
                "correct": success, "false_report": False, "correct_give_up": None,
                "sim_time_s": time}

    rows = [row("w1", "default", 100.0), row("w1", "learned", 50.0),
            row("w2", "default", 100.0), row("w2", "learned", 80.0),
            row("w3", "default", 100.0), row("w3", "learned", 900.0, success=False)]
    pairs = priors_pairs(rows, "switching")
    assert len(pairs) == 3 and all(a["priors"] == "learned" for a, _ in pairs)
    assert sorted(priors_ratios(pairs)) == [0.5, 0.8]
    full = [{**{c: None for c in COLUMNS}, **r} for r in rows]
    text = render(full, {"name": "p"}, Path("/tmp/p-report.md"))
    assert "## Learned priors: default against learned" in text
    assert "| switching | default | 3 | 3/3 = 100%" in text
    assert "| switching | learned | 3 | 2/3 = 67%" in text
    assert "0.65 [" in text and "(n 2)" in text
    assert "## Learned priors: by target" in text


# ---- the store read without writing -------------------------------------------------------


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_read_only_store_refuses_updates_and_a_missing_one(tmp_path):
    path = tmp_path / "exp.sqlite3"
    with pytest.raises(ExperienceError, match="no experience store there"):
        ExperienceStore(path, readonly=True)
    assert not path.exists()
    with ExperienceStore(path) as store:
        store.update("b1", Evidence(rooms={("cup", "kitchen"): (1.0, 1.0)}))
    before = _digest(path)
    with ExperienceStore(path, readonly=True) as store:
        with pytest.raises(ExperienceError, match="read-only"):
            store.update("b1", Evidence(rooms={("cup", "kitchen"): (1.0, 1.0)}))
        assert store.scopes() == ["all", "building:b1"]
    assert _digest(path) == before


def test_the_spec_key_learn_goes_with_a_store():
    spec = EpisodeSpec.from_dict({"target": "cup", "experience": "e.sqlite3", "learn": False})
    assert spec.learn is False
    assert EpisodeSpec.from_dict({"target": "cup", "experience": "e.sqlite3"}).learn
    with pytest.raises(EpisodeError, match="'learn' says whether"):
        EpisodeSpec.from_dict({"target": "cup", "learn": False})
    with pytest.raises(EpisodeError, match="'learn' must be true or false"):
        EpisodeSpec.from_dict({"target": "cup", "experience": "e.sqlite3", "learn": "no"})


def test_an_episode_of_the_learned_arm_leaves_the_store_as_it_was(tmp_path):
    """A real (short) episode with `learn: false` plans with the store and writes nothing;
    the same episode with learning adds to it."""
    path = tmp_path / "exp.sqlite3"
    with ExperienceStore(path) as store:
        store.update("gen-office-430-moved",
                     Evidence(rooms={("cup", "kitchen"): (0.0, 3.0)}, categories={"office": 2}))
    before = _digest(path)
    spec = {"target": "cup", "generate": {"seed": 430, "table": "moved"},
            "time_budget_s": 60.0, "seed": 1, "experience": str(path),
            "building": "gen-office-430-moved"}
    summary = run_episode({**spec, "learn": False})
    assert summary["experience"] == {"store": "exp.sqlite3", "building": "gen-office-430-moved",
                                     "updated": False, "learn": False}
    assert _digest(path) == before
    summary = run_episode(spec)
    assert summary["experience"]["updated"] is True
    assert _digest(path) != before
