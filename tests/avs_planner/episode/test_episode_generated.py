"""A building no test was tuned on: a generated floor plan, end to end (issue 19)."""

import pytest

from avs_planner.episode import run_episode
from avs_planner.episode.worlds import generated_targets


def test_the_switching_planner_finds_an_object_in_a_generated_world() -> None:
    targets = dict(generated_targets(1, "office", 3))
    assert targets["book"], "world 1 (3 rooms) was generated with a book in it"
    summary = run_episode({"generate": {"seed": 1, "style": "office", "rooms": 3},
                           "target": "book", "seed": 0})
    assert summary["world"] == "office_1"
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]


@pytest.mark.slow
@pytest.mark.parametrize("world", [0, 1, 2])
def test_absent_labels_are_given_up_on_without_a_false_report(world: int) -> None:
    absent = [label for label, there in generated_targets(world, "office", 3) if not there]
    summary = run_episode({"generate": {"seed": world, "style": "office", "rooms": 3},
                           "target": absent[0], "seed": 0})
    assert summary["outcome"] in ("gave_up", "timeout") and summary["object"] is None
