"""The detector watches while the robot moves: a target in plain view is found without a
DT search, and the planner hears of it through the monitor (it matches the plan's virtual
object or settles the goal)."""

import pytest

from avs_planner.harness import Episode, EpisodeSpec, run_episode

WORLD = """
name: in-view
size: [10.0, 6.0]
rooms:
  - {name: hall, category: corridor, rect: [0.0, 0.0, 10.0, 2.0]}
  - {name: kitchen, category: kitchen, rect: [0.0, 2.0, 5.0, 6.0]}
  - {name: office, category: office, rect: [5.0, 2.0, 10.0, 6.0]}
doors:
  - {rooms: [hall, kitchen], at: [2.5, 2.0], width: 0.9}
  - {rooms: [hall, office], at: [7.5, 2.0], width: 0.9}
furniture:
  - {name: table1, label: table, room: kitchen, pose: [2.5, 4.5, 0.0], size: [1.2, 0.8, 0.75]}
  - {name: desk1, label: desk, room: office, pose: [7.5, 5.4, 0.0], size: [1.6, 0.8, 0.74]}
objects:
  - {name: cereal1, label: cerealbox, on: table1, offset: [0.0, -0.2], size: [0.2, 0.07, 0.3]}
robot: {model: pioneer, start: [2.5, 3.0, 1.5708]}
"""


def test_a_target_in_plain_view_is_found_without_a_dt_search() -> None:
    summary = run_episode({"target": "cerealbox", "world_file": WORLD, "seed": 0})
    assert summary["outcome"] == "found" and summary["correct"]
    assert summary["dt_calls"] == 0
    assert summary["sim_time_s"] < 30.0


def test_seen_targets_reach_the_monitor_with_the_next_step() -> None:
    spec = EpisodeSpec.from_dict({"target": "cerealbox", "world_file": WORLD, "seed": 0})
    episode = Episode(spec)
    try:
        def target_seen() -> list[str]:  # supports seen on the way are reported too
            return [o for o, atoms in episode.executor.seen_while_moving.items()
                    if ("label-of", o, "cerealbox") in atoms]

        for _ in range(4):  # each look confirms a sighting 9 times in 10
            episode.executor.look_around()
            if target_seen():
                break
        assert target_seen(), "the cereal box in view was not confirmed"
        oid = target_seen()[0]
        atoms = episode.executor.seen_while_moving[oid]
        assert ("label-of", oid, "cerealbox") in atoms and ("detected", oid) in atoms
        assert episode.mind.objects[oid].label == "cerealbox"
        # nothing is watched before the search starts (Fig. 3f of the active visual search
        # paper: pre-built maps)
        episode.executor.watching = False
        assert episode.executor.watch() is None
    finally:
        episode.trace.close()
        episode.robot.world.close()


def test_a_target_seen_in_the_first_frame_ends_the_look_around_once_the_map_places_it() -> None:
    """The first frame comes before the first place, so a target confirmed in it waits for
    the scan behind to give it a room; the robot turns straight to that scan (no frame at
    the headings between: they cost a second and can show nothing that matters now), and
    once placed, the target is found, and the robot does not turn on through the rest of
    its headings."""
    import dataclasses
    import math

    spec = EpisodeSpec.from_dict({"target": "cerealbox", "world_file": WORLD, "seed": 0})
    for _ in range(4):  # the first frame confirms a sighting 9 times in 10
        episode = Episode(spec)
        try:
            executor = episode.executor
            executor.config = dataclasses.replace(executor.config, look_headings=6)
            start = executor.robot.pose[2]
            clock = executor.robot.clock
            executor.look_around()
            found = [o for o in episode.mind.objects.values() if o.label == "cerealbox"]
            if not found:
                continue
            turned = (executor.robot.pose[2] - start) % (2 * math.pi)
            assert turned == pytest.approx(math.pi, abs=0.1), \
                "the look went on past the half turn that placed the target"
            assert executor.robot.clock - clock == pytest.approx(
                _half_turn_look(spec), abs=0.01), \
                "the robot stopped at headings before the half turn"
            return
        finally:
            episode.trace.close()
            episode.robot.world.close()
    raise AssertionError("the cereal box ahead was never confirmed")


def _half_turn_look(spec: EpisodeSpec) -> float:
    """Seconds of the same first look with two headings: a frame, the half turn, a scan."""
    import dataclasses

    episode = Episode(spec)
    try:
        executor = episode.executor
        executor.config = dataclasses.replace(executor.config, look_headings=2)
        clock = executor.robot.clock
        executor.look_around()
        return executor.robot.clock - clock
    finally:
        episode.trace.close()
        episode.robot.world.close()


def test_a_target_found_in_a_look_around_where_the_map_has_places_ends_it_there() -> None:
    """Once the map has places (a later look, or the first in a building the robot
    remembers), a target confirmed at some heading ends the look around at once: the
    report's verification looks from there, and the scan behind would serve a search that
    is over."""
    import dataclasses
    import math

    spec = EpisodeSpec.from_dict({"target": "cerealbox", "world_file": WORLD, "seed": 0})
    for _ in range(4):  # a frame confirms a sighting 9 times in 10
        episode = Episode(spec)
        try:
            executor, robot = episode.executor, episode.executor.robot
            executor.config = dataclasses.replace(executor.config, look_headings=6)
            executor.watching = False  # a first look that maps the hall but sees no target
            executor.look_around()
            assert episode.mind.place_map.current_place is not None
            assert not [o for o in episode.mind.objects.values() if o.label == "cerealbox"]
            executor.watching = True
            robot.turn_to(0.0)  # the table a quarter turn to the left
            executor.look_around()
            if not [o for o in episode.mind.objects.values() if o.label == "cerealbox"]:
                continue
            turned = (robot.pose[2] - 0.0) % (2 * math.pi)
            assert turned < math.pi - 0.1, "the look went on past the heading that found it"
            return
        finally:
            episode.trace.close()
            episode.robot.world.close()
    raise AssertionError("the cereal box to the left was never confirmed")
