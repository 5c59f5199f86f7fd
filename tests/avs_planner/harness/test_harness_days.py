"""Generated worlds of a later day in episode specs, and the labels recorded per day; the
episode spec's `memory` and `since_s` keys (read by the building memory)."""

from __future__ import annotations

import re

import pytest

from avs_planner.episode.errors import EpisodeError
from avs_planner.harness.runner import EpisodeSpec
from avs_planner.harness.sim_robot import generated_spec
from avs_planner.harness.worlds import generated_instances, generated_targets
from sim.generate import generate_world


def test_a_generated_spec_of_a_later_day_is_that_days_world() -> None:
    spec = generated_spec({"seed": 6, "style": "office", "day": 2, "move": 1.0, "doors": 0.3})
    world = generate_world(6, "office", day=2, move=1.0, doors=0.3)
    assert {o.name: o.on for o in spec.objects} == {o["name"]: o["on"]
                                                    for o in world.data["objects"]}
    day0 = generated_spec({"seed": 6, "style": "office"})
    assert {o.name: o.on for o in spec.objects} != {o.name: o.on for o in day0.objects}


@pytest.mark.parametrize(("generate", "message"), [
    ({"seed": 1, "day": -2}, "generate.day: expected an integer >= 0, got -2"),
    ({"seed": 1, "day": "3"}, "generate.day: expected an integer >= 0, got '3'"),
    ({"seed": 1, "move": 2}, "generate.move: expected a probability in [0, 1], got 2"),
    ({"seed": 1, "doors": True}, "generate.doors: expected a probability in [0, 1]"),
    ({"seed": 1, "days": 3}, "expected keys seed (required), style, rooms, surprise, day, "
                             "move, doors, table; got ['days', 'seed']"),
])
def test_bad_day_keys_are_refused_naming_the_key(generate: dict, message: str) -> None:
    with pytest.raises(EpisodeError, match=re.escape(message)):
        generated_spec(generate)


def test_the_generators_record_is_the_days_own() -> None:
    day = {"day": 4, "move": 1.0}
    world = generate_world(8, "lab", day=4, move=1.0)
    counts: dict[str, int] = {}
    for obj in world.data["objects"]:
        counts[obj["label"]] = counts.get(obj["label"], 0) + 1
    assert generated_instances(8, "lab", **day) == dict(sorted(counts.items()))
    assert generated_instances(8, "lab", **day) == generated_instances(8, "lab")  # none leave
    present = set(world.labels_present())
    assert all((label in present) == there
               for label, there in generated_targets(8, "lab", **day))


def test_the_episode_spec_reads_memory_and_since_s() -> None:
    spec = EpisodeSpec.from_dict({"target": "cup", "memory": "/tmp/m", "since_s": 86400})
    assert spec.memory == "/tmp/m" and spec.since_s == 86400.0
    plain = EpisodeSpec.from_dict({"target": "cup"})
    assert plain.memory is None and plain.since_s == 3600.0
    for bad in (-1, "a day", True, float("nan")):
        with pytest.raises(EpisodeError, match="'since_s' must be a number >= 0"):
            EpisodeSpec.from_dict({"target": "cup", "since_s": bad})
