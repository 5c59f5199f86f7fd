"""Generated worlds as the planning side may see them: names, benchmark targets, label counts.

Campaigns and benchmarks ask which labels to search for in a generated world (two present, one
absent) and how many objects of each label it holds (tasks that count every instance); the
answer comes from the generator's own record of what it placed, which is the experimenter's
knowledge, never the robot's. A world of a later day (`day`, `move`, `doors`: the building
with objects moved and doors toggled, see `sim.generate`) is asked about as that day's world,
and one of another placement table (`table: moved`) as that table built it; these keywords
(`**days`) go into the world's `generate` mapping as they are.
"""

from __future__ import annotations

from typing import Any

from avs_planner.episode.errors import EpisodeError


def _world(seed: int, style: str, rooms: int | None, surprise: float,
           days: dict[str, Any]) -> Any:
    """The generated world (a `sim.generate.GeneratedWorld`) of these arguments; `days` may
    hold day, move and doors."""
    from avs_planner.harness.sim_robot import generate_world_of
    from sim.errors import SimError

    try:
        return generate_world_of({"seed": seed, "style": style, "rooms": rooms,
                                  "surprise": surprise, **days})
    except SimError as exc:
        raise EpisodeError(f"generate: {exc}") from exc


def generated_targets(seed: int, style: str = "office", rooms: int | None = None,
                      present: int = 2, absent: int = 1, surprise: float = 0.25,
                      **days: Any) -> list[tuple[str, bool]]:
    """(label, present in the world) for a benchmark on the generated world `seed` (of day
    `day` when `days` says so: day, move, doors)."""
    from sim.errors import SimError

    world = _world(seed, style, rooms, surprise, days)
    try:
        labels = world.targets(seed, present, absent)
    except SimError as exc:
        raise EpisodeError(f"generate: {exc}") from exc
    there = set(world.labels_present())
    return [(label, label in there) for label in labels]


def generated_name(seed: int, style: str = "office", rooms: int | None = None,
                   table: str = "default") -> str:
    """The name a generated world is known by in tables and run ids (`-<table>` at the end
    for a placement table other than the default: `gen-office-400-moved`)."""
    return (f"gen-{style}-{seed}" + (f"-r{rooms}" if rooms is not None else "")
            + ("" if table == "default" else f"-{table}"))


def generated_instances(seed: int, style: str = "office", rooms: int | None = None,
                        surprise: float = 0.25, **days: Any) -> dict[str, int]:
    """How many objects of each small-object label the generated world `seed` holds (labels
    present only, sorted), from the generator's own record: the experimenter's knowledge, for
    campaigns that ask for tasks over a building's labels, never the robot's. `days` (day,
    move, doors) asks about a later day of the building: objects move, none comes or goes, so
    the counts are day 0's, read from the day's own world all the same."""
    world = _world(seed, style, rooms, surprise, days)
    counts: dict[str, int] = {}
    for obj in world.data["objects"]:
        counts[obj["label"]] = counts.get(obj["label"], 0) + 1
    return dict(sorted(counts.items()))


def placement_tables() -> tuple[str, ...]:
    """The generator's placement tables by name (`default`, `moved`: sim/generation/)."""
    from sim.generation.table import TABLES

    return tuple(TABLES)
