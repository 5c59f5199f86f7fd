"""Generated floor plans from development seeds, end to end (the held-out range, 10000 and
up, is for evaluation only: docs/experiments.md)."""

import pytest

from avs_planner.harness import run_episode
from avs_planner.harness.worlds import generated_targets


def test_the_switching_planner_finds_an_object_in_a_generated_world() -> None:
    targets = dict(generated_targets(1, "office", 3))
    assert targets["book"], "world 1 (3 rooms) was generated with a book in it"
    summary = run_episode({"generate": {"seed": 1, "style": "office", "rooms": 3},
                           "target": "book", "seed": 0})
    assert summary["world"] == "office_1"
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]


def _absent(world: int) -> dict:
    absent = [label for label, there in generated_targets(world, "office", 3) if not there]
    return run_episode({"generate": {"seed": world, "style": "office", "rooms": 3},
                        "target": absent[0], "seed": 0})


def test_an_absent_label_is_given_up_on_naming_the_probability_left() -> None:
    """A development world (office 0, 3 rooms): the target is not in it. The planner gives up
    (not a timeout) without a false report, and says how likely the space it did not search
    still was to hold the target."""
    summary = _absent(0)
    assert summary["outcome"] == "gave_up", summary["reason"]
    assert summary["object"] is None
    assert "P(target in space not yet searched) = " in summary["reason"]


@pytest.mark.slow
@pytest.mark.parametrize("world", [1, 2])
def test_absent_labels_are_given_up_on_without_a_false_report(world: int) -> None:
    summary = _absent(world)
    assert summary["outcome"] == "gave_up", summary["reason"]
    assert summary["object"] is None
