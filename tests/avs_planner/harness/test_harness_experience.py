"""The experience store's wiring without running an episode: the episode spec's `experience`
and `building`, the removed `learn_file` option, the `avs knowledge` commands, and no
process-wide learning state."""

from __future__ import annotations

import json

import pytest

import avs_planner.episode.experience as evidence_module
import avs_planner.strategies.qsr as qsr_strategy
import conceptual_map.knowledge.experience as store_module
import conceptual_map.qsr.learning as qsr_learning
from avs_planner.cli import main
from avs_planner.episode import EpisodeError
from avs_planner.harness.runner import Episode, EpisodeSpec
from conceptual_map.knowledge.experience import Evidence, ExperienceStore


def _spec(**extra):
    return {"target": "cup", "world": "office", **extra}


def test_the_spec_takes_a_store_and_a_building_id() -> None:
    spec = EpisodeSpec.from_dict(_spec(experience="runs/exp.sqlite", building="lab-2.west_1"))
    assert (spec.experience, spec.building) == ("runs/exp.sqlite", "lab-2.west_1")
    plain = EpisodeSpec.from_dict(_spec())
    assert plain.experience is None and plain.building is None


@pytest.mark.parametrize("bad", ["", "../etc", "a b", "-lead", "x" * 65, 7, "bureau/2"])
def test_the_spec_refuses_a_bad_building_id_naming_the_key(bad) -> None:
    with pytest.raises(EpisodeError, match="'building' must be an id"):
        EpisodeSpec.from_dict(_spec(building=bad))


def test_the_spec_refuses_an_experience_that_is_not_a_path() -> None:
    with pytest.raises(EpisodeError, match="'experience' must be the path"):
        EpisodeSpec.from_dict(_spec(experience=""))
    with pytest.raises(EpisodeError, match="'experience' must be the path"):
        EpisodeSpec.from_dict(_spec(experience=["a"]))


def test_an_episode_on_a_file_that_is_not_a_store_is_a_clear_error(tmp_path) -> None:
    junk = tmp_path / "notes.txt"
    junk.write_text("hello " * 100)
    with pytest.raises(EpisodeError, match="'experience'.*not an experience store"):
        Episode(EpisodeSpec.from_dict(_spec(experience=str(junk))))


@pytest.mark.parametrize("strategy", ["qsr", "supporting-planes", "random"])
def test_learn_file_is_refused_saying_what_to_use_instead(strategy, tmp_path) -> None:
    for value in (str(tmp_path / "x.yaml"), ""):
        with pytest.raises(EpisodeError) as err:
            EpisodeSpec.from_dict(_spec(strategy=strategy,
                                        strategy_options={"learn_file": value}))
        message = str(err.value)
        assert "'learn_file' was removed" in message
        assert "--experience PATH" in message and "experience store" in message
    assert not (tmp_path / "x.yaml").exists()


def test_learning_keeps_no_module_level_state() -> None:
    """QSR learning and the store keep nothing in the process: no mutable module globals."""
    for module in (qsr_strategy, qsr_learning, store_module, evidence_module):
        mutable = [name for name, value in vars(module).items()
                   if isinstance(value, dict | list | set) and not name.startswith("__")]
        assert mutable == [], (module.__name__, mutable)


def _store(path) -> None:
    with ExperienceStore(path) as store:
        store.update("b1", Evidence(rooms={("cup", "kitchen"): (3.0, 2.0)},
                                    categories={"kitchen": 1.0}))
        store.update("b2", Evidence(rooms={("cup", "kitchen"): (0.0, 1.0)}))


def test_knowledge_show_export_and_reset(tmp_path, capsys) -> None:
    path = tmp_path / "exp.sqlite"
    _store(path)
    assert main(["knowledge", "show", "--store", str(path), "--format", "json"]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert shown["episodes"] == {"all": 2, "building:b1": 1, "building:b2": 1}
    cup = next(r for r in shown["rates"] if r["label"] == "cup")
    assert cup["category"] == "kitchen" and cup["file"] == 0.3
    assert cup["learned"] == pytest.approx(round((2 * 0.3 + 3) / (2 + 3), 4))
    assert (cup["found"], cup["exposure"]) == (3.0, 3.0)
    assert main(["knowledge", "show", "--store", str(path), "--building", "b1"]) == 0
    assert "scope: building:b1" in capsys.readouterr().out  # yaml by default
    assert main(["knowledge", "reset", "--store", str(path), "--building", "b1"]) == 0
    assert "reset building:b1" in capsys.readouterr().out
    assert main(["knowledge", "export", "--store", str(path), "--format", "json"]) == 0
    exported = json.loads(capsys.readouterr().out)
    assert sorted(exported["scopes"]) == ["all", "building:b2"]
    assert main(["knowledge", "reset", "--store", str(path)]) == 0
    capsys.readouterr()
    assert main(["knowledge", "export", "--store", str(path), "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["scopes"] == {}


def test_knowledge_commands_refuse_a_missing_or_damaged_store(tmp_path, capsys) -> None:
    missing = tmp_path / "none.sqlite"
    assert main(["knowledge", "show", "--store", str(missing)]) == 1
    assert "no experience store there" in capsys.readouterr().err
    assert not missing.exists()  # show never makes one
    junk = tmp_path / "junk.sqlite"
    junk.write_text("junk " * 100)
    assert main(["knowledge", "reset", "--store", str(junk)]) == 1
    assert "not an experience store" in capsys.readouterr().err
    _store(tmp_path / "ok.sqlite")
    assert main(["knowledge", "show", "--store", str(tmp_path / "ok.sqlite"),
                 "--building", "../x"]) == 1
    assert "building id" in capsys.readouterr().err


def test_simulate_refuses_a_building_without_a_store_and_a_damaged_store(tmp_path,
                                                                          capsys) -> None:
    out = str(tmp_path / "run")
    assert main(["simulate", "--target", "cup", "--building", "b1", "--out", out]) == 1
    assert "use it with --experience PATH" in capsys.readouterr().err
    junk = tmp_path / "junk.sqlite"
    junk.write_text("junk " * 100)
    assert main(["simulate", "--target", "cup", "--experience", str(junk), "--out", out]) == 1
    assert "--experience" in capsys.readouterr().err
