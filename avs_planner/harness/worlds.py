"""Generated worlds as the planning side may see them: names, benchmark targets, label counts.

Campaigns and benchmarks ask which labels to search for in a generated world (two present, one
absent) and how many objects of each label it holds (tasks that count every instance); the
answer comes from the generator's own record of what it placed, which is the experimenter's
knowledge, never the robot's.
"""

from __future__ import annotations

from avs_planner.episode.errors import EpisodeError


def generated_targets(seed: int, style: str = "office", rooms: int | None = None,
                      present: int = 2, absent: int = 1, surprise: float = 0.25
                      ) -> list[tuple[str, bool]]:
    """(label, present in the world) for a benchmark on the generated world `seed`."""
    from sim.errors import SimError
    from sim.generate import generate_world

    try:
        world = generate_world(seed, style, rooms, surprise)
        labels = world.targets(seed, present, absent)
    except SimError as exc:
        raise EpisodeError(f"generate: {exc}") from exc
    there = set(world.labels_present())
    return [(label, label in there) for label in labels]


def generated_name(seed: int, style: str = "office", rooms: int | None = None) -> str:
    """The name a generated world is known by in tables and run ids."""
    return f"gen-{style}-{seed}" + (f"-r{rooms}" if rooms is not None else "")


def generated_instances(seed: int, style: str = "office", rooms: int | None = None,
                        surprise: float = 0.25) -> dict[str, int]:
    """How many objects of each small-object label the generated world `seed` holds (labels
    present only, sorted), from the generator's own record: the experimenter's knowledge, for
    campaigns that ask for tasks over a building's labels, never the robot's."""
    from sim.errors import SimError
    from sim.generate import generate_world

    try:
        world = generate_world(seed, style, rooms, surprise)
    except SimError as exc:
        raise EpisodeError(f"generate: {exc}") from exc
    counts: dict[str, int] = {}
    for obj in world.data["objects"]:
        counts[obj["label"]] = counts.get(obj["label"], 0) + 1
    return dict(sorted(counts.items()))
