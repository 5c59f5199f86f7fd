"""One category vocabulary: worlds speak the knowledge base's categories (however spelled),
every place reading becomes evidence or a warning in the trace, never silence."""

import pytest

from avs_planner.episode import EpisodeError
from avs_planner.harness import Episode, EpisodeSpec, run_episode

WORLD = """
name: two-rooms
size: [8.0, 5.0]
rooms:
  - {name: hall, category: Corridor, rect: [0.0, 0.0, 8.0, 2.0]}
  - {name: meet, category: CATEGORY, rect: [0.0, 2.0, 8.0, 5.0]}
doors:
  - {rooms: [hall, meet], at: [4.0, 2.0], width: 1.0}
furniture:
  - {name: table1, label: table, room: meet, pose: [4.0, 3.8, 0.0], size: [1.2, 0.8, 0.75]}
objects:
  - {name: cup1, label: cup, on: table1, offset: [0.1, 0.0], size: [0.08, 0.08, 0.1]}
robot: {model: pioneer, start: [2.0, 1.0, 0.0]}
"""


def test_people_s_spelling_of_a_category_is_used_as_evidence() -> None:
    events: list[dict] = []
    spec = {"target": "cup", "world_file": WORLD.replace("CATEGORY", "meeting room"),
            "start": [4.0, 3.0, 0.0]}
    episode = Episode(EpisodeSpec.from_dict(spec), events.append)
    try:
        episode.executor.look_around()
        assert episode.mind.classified, "the reading in the meeting room was not used"
        assert not [e for e in events if e["type"] == "warning"]
    finally:
        episode.trace.close()
        episode.robot.world.close()


def test_unknown_category_is_a_clear_error_naming_the_room() -> None:
    spec = {"target": "cup", "world_file": WORLD.replace("CATEGORY", "garage")}
    with pytest.raises(EpisodeError, match=r"rooms\[1\] \(meet\): category 'garage' is not in "
                                           r"the knowledge base \(known: corridor, "):
        run_episode(spec)


def test_a_reading_the_knowledge_cannot_use_is_a_warning() -> None:
    from avs_planner.episode.mind import Mind

    mind = Mind()
    assert "no place" in mind.observe_appearance("kitchen")
    events: list[dict] = []
    spec = {"target": "cup", "world_file": WORLD.replace("CATEGORY", "meeting_room")}
    episode = Episode(EpisodeSpec.from_dict(spec), events.append)
    try:
        episode.executor.look_around()
        episode.robot.classify_place = lambda: "garage"  # a classifier of another vocabulary
        episode.mind.classified.clear()
        episode.executor.sensing.classify()
        warnings = [e for e in events if e["type"] == "warning"]
        assert warnings and "garage_like" in warnings[0]["detail"]
    finally:
        episode.trace.close()
        episode.robot.world.close()
