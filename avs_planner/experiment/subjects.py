"""What a campaign searches: (world, target, start) subjects from scenarios or worlds × targets.

A target is one label or a task of several objects (`harness/tasks.py`: all or any of several
labels, or every instance of one); docs/experiments.md has the forms a campaign file takes. A
subject carries the outcome to expect: a scenario's own; for a world file, `found` when the
world holds an object (or furniture) with the target's label, else `gave_up` (a task: `found`
when it holds every label of an "all" task, some label of an "any" task, an instance of a
counted label); for a generated world with `targets: auto`, the generator's (label, present)
list, and for tasks over the building's labels (`{auto: present, ...}`), `found`.

Tasks over a generated building's labels take them from the generator's record of what it
placed (`harness/worlds.py`: the experimenter's knowledge, never the robot's): the labels
present, sorted, then shuffled by `random.Random(building seed)`; an `all: N` or `any: N` task
takes the first N of that order (so `any: 2` takes two of the labels `all: 3` takes), and
`count: all` every label with at least `MIN_COUNTED` instances, in that order (`pick: N`: the
first N of them); `labels: N` is a single search for each of the first N (no task).
"""

from __future__ import annotations

import random
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from avs_planner.errors import AvsError
from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.sequences import Sequence, task_label
from avs_planner.experiment.target_forms import (
    EXPECTED,
    FORM_KEYS,
    Wanted,
    known_label,
    target_entries,
    unique_wanted,
)
from avs_planner.experiment.values import Where, parse_seeds

DEFAULT_TABLE = "default"  # the generator's default placement table (sim.generation.table)
_WORLD_KEYS = {"world", "generate", "targets", "start_room", "start"}
_GENERATE_KEYS = {"seeds", "style", "rooms", "table"}


@dataclass(frozen=True)
class Subject:
    """A world, a target (a label, or a task of several objects) and a start: the part of an
    episode a campaign varies least."""

    world: str  # display name
    group: str  # scenario name, world name or generator group: a row of the report
    target: str  # the label; for a task, its name ("cup and book", "every chair")
    expected: str | None  # found / gave_up / None (unknown)
    scenario: str | None
    spec: Mapping[str, Any]  # episode keys: world or generate, start, start_room, ...
    # a task of several objects: its episode keys (targets, mode, count, and stop_below when
    # the campaign gives it); None for one label
    task: Mapping[str, Any] | None = None
    # a task of a campaign sequence: the day of the building (and the task's index in the
    # sequence); None otherwise
    day: int | None = None

    @property
    def kind(self) -> str:
        """`all`, `any` or `count` for a task of several objects; "" for one label."""
        if self.task is None:
            return ""
        return "count" if self.task["count"] == "all" else str(self.task["mode"])

    @property
    def labels(self) -> tuple[str, ...]:
        """The labels searched for."""
        return (self.target,) if self.task is None else tuple(self.task["targets"])

    def episode_keys(self) -> dict[str, Any]:
        """What the episode spec says of the target: `target`, or a task's keys."""
        if self.task is None:
            return {"target": self.target}
        return {k: list(v) if k == "targets" else v for k, v in self.task.items()}


def scenario_subjects(value: Any, where: Where, base: Path) -> Iterator[Subject]:
    from avs_planner.harness.scenarios import load_scenario

    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value:
        raise where.error("a non-empty list of scenario names (a-f) or scenario files")
    for i, name in enumerate(value):
        if not isinstance(name, str):
            raise where.at(i).error(f"a scenario name or path, got {name!r}")
        ref = str(base / name) if name.endswith((".yaml", ".yml")) else name
        try:
            scenario = load_scenario(ref)
        except AvsError as exc:
            raise where.at(i).error(str(exc)) from None
        spec = {k: v for k, v in scenario.spec.items() if k not in ("target", "seed")}
        world = Path(str(spec.get("world", "office"))).stem
        yield Subject(world, scenario.name, scenario.spec["target"], scenario.expected,
                      scenario.name, spec)


def world_subjects(worlds: Any, targets: Any, where: Where, base: Path) -> Iterator[Subject]:
    if not isinstance(worlds, list) or not worlds:
        raise where.at("worlds").error("a non-empty list of world names, paths or "
                                       "{generate: {seeds, style, rooms}} entries")
    for i, entry in enumerate(worlds):
        at = where.at("worlds").at(i)
        if isinstance(entry, str):
            entry = {"world": entry}
        if not isinstance(entry, dict) or ("world" in entry) == ("generate" in entry):
            raise at.error("a world name or path, {world: ..., targets: ...} or "
                           "{generate: {seeds, style, rooms}, targets: ...}")
        if set(entry) - _WORLD_KEYS:
            raise at.error(f"unknown keys {sorted(set(entry) - _WORLD_KEYS)}; allowed: "
                           f"{sorted(_WORLD_KEYS)}")
        if "generate" in entry:
            yield from _generated(entry, _targets_for(entry, targets, "generated", at, where),
                                  at)
        else:
            yield from _from_file(entry, targets, at, where, base)


def _targets_for(entry: dict[str, Any], top: Any, key: str, at: Where, where: Where
                 ) -> tuple[Any, Where]:
    """The entry's own targets, else the top-level mapping's entry for `key`, else the list."""
    if "targets" in entry:
        return entry["targets"], at.at("targets")
    if isinstance(top, dict) and not set(top) & FORM_KEYS:
        if key not in top:
            raise where.at("targets").error(f"no targets for world {key!r} (keys: "
                                            f"{', '.join(map(str, top))})")
        return top[key], where.at("targets").at(key)
    if top is None:
        raise at.error("no targets: give 'targets' at the top or in this entry")
    return top, where.at("targets")


def _from_file(entry: dict[str, Any], top: Any, at: Where, where: Where, base: Path
               ) -> Iterator[Subject]:
    from avs_planner.harness.sim_robot import load_spec

    text = entry["world"]
    if not isinstance(text, str) or not text:
        raise at.at("world").error(f"a built-in world name or a world file path, got {text!r}")
    ref = str((base / text).resolve()) if text.endswith((".yaml", ".yml")) else text
    start = entry.get("start")
    if start is not None and (not isinstance(start, list) or len(start) != 3 or not all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in start)):
        raise at.at("start").error(f"a start pose is [x, y, yaw], got {start!r}")
    try:
        world = load_spec(ref, None, start, entry.get("start_room"))
    except AvsError as exc:
        raise at.error(str(exc)) from None
    labels = {o.label for o in world.objects} | {f.label for f in world.furniture}
    value, t_at = _targets_for(entry, top, text, at, where)
    spec = {"world": ref, **{k: entry[k] for k in ("start", "start_room") if k in entry}}
    name = Path(text).stem
    entries = target_entries(value, t_at, generated=False)
    for wanted in unique_wanted([w for e in entries for w in e.resolve(None)]):
        yield Subject(name, name, wanted.name, wanted.expected_in(labels), None, spec,
                      wanted.task)


def _generated(entry: dict[str, Any], targets: tuple[Any, Where], at: Where
               ) -> Iterator[Subject]:
    style, rooms, group, seeds, table = _generate_entry(entry, at)
    value, t_at = targets
    entries = target_entries(value, t_at, generated=True)
    for seed in seeds:
        spec = {"generate": {"seed": seed, "style": style, "rooms": rooms, **_table(table)}}
        building = Building(seed, style, rooms, table)
        name = generated_name(seed, style, rooms, table)
        for wanted in unique_wanted([w for e in entries for w in e.resolve(building)]):
            yield Subject(name, group, wanted.name, wanted.expected, None, spec, wanted.task)


def _generate_entry(entry: dict[str, Any], at: Where
                    ) -> tuple[str, int | None, str, list[int], str]:
    """A `{generate: {seeds, style, rooms, table}}` entry: style, rooms, group, building
    seeds and placement table (`default` unless given)."""
    gen = entry["generate"]
    g_at = at.at("generate")
    if not isinstance(gen, dict) or "seeds" not in gen or set(gen) - _GENERATE_KEYS:
        raise g_at.error(f"a mapping with 'seeds' and optionally 'style', 'rooms', 'table' "
                         f"(keys {sorted(_GENERATE_KEYS)})")
    style, rooms = gen.get("style", "office"), gen.get("rooms")
    if not isinstance(style, str):
        raise g_at.at("style").error(f"a world style name, got {style!r}")
    if rooms is not None and (isinstance(rooms, bool) or not isinstance(rooms, int)
                              or rooms < 1):
        raise g_at.at("rooms").error(f"a positive number of rooms, got {rooms!r}")
    table = gen.get("table", DEFAULT_TABLE)
    tables = placement_tables()
    if not isinstance(table, str) or table not in tables:
        raise g_at.at("table").error(f"a placement table, one of {', '.join(tables)}; got "
                                     f"{table!r}")
    group = (f"gen-{style}" + (f"-r{rooms}" if rooms is not None else "")
             + ("" if table == DEFAULT_TABLE else f"-{table}"))
    return style, rooms, group, parse_seeds(gen["seeds"], g_at.at("seeds")), table


def _table(table: str) -> dict[str, str]:
    """The `table` key of an episode's `generate` mapping: only for a table other than the
    default (so the specs of default worlds stay as they were, and their records match)."""
    return {} if table == DEFAULT_TABLE else {"table": table}


def placement_tables() -> tuple[str, ...]:
    """The generator's placement tables by name (`sim.generation.table.TABLES`)."""
    from avs_planner.harness.worlds import placement_tables as tables

    return tables()


def sequence_subjects(worlds: Any, sequence: Sequence, where: Where) -> Iterator[Subject]:
    """The tasks of a campaign sequence (`sequences.py`): per generated building, task i on
    day i, its target a label the building holds that day (expected: found)."""
    if not isinstance(worlds, list) or not worlds:
        raise where.at("worlds").error("a non-empty list of {generate: {seeds, style, rooms}} "
                                       "entries (a sequence runs on generated buildings)")
    for i, entry in enumerate(worlds):
        at = where.at("worlds").at(i)
        if not isinstance(entry, dict) or "generate" not in entry:
            raise at.error("a sequence runs on generated buildings: give {generate: {seeds, "
                           "style, rooms}}")
        if set(entry) - {"generate"}:
            raise at.error(f"unknown keys {sorted(set(entry) - {'generate'})}: with "
                           f"'sequence', an entry is {{generate: {{seeds, style, rooms}}}} "
                           f"(targets are drawn per task)")
        style, rooms, group, seeds, table = _generate_entry(entry, at)
        for seed in seeds:
            name = generated_name(seed, style, rooms, table)
            for day in range(sequence.tasks):
                days = {**sequence.generate(day), **_table(table)}
                try:
                    counts = generated_instances(seed, style, rooms, **days)
                except AvsError as exc:
                    raise at.error(f"world seed {seed}: {exc}") from None
                labels = [label for label, n in counts.items() if n > 0]
                if not labels:
                    raise at.error(f"world seed {seed} ({name}) holds no small objects on "
                                   f"day {day}")
                label = known_label(task_label(seed, day, labels), at)
                spec = {"generate": {"seed": seed, "style": style, "rooms": rooms, **days}}
                yield Subject(name, group, label, "found", None, spec, None, day)


@dataclass(frozen=True)
class Building:
    """A generated world, as the target entries that depend on it need it."""

    seed: int
    style: str
    rooms: int | None
    table: str = DEFAULT_TABLE

    def targets(self, where: Where) -> list[Wanted]:
        """The generator's own targets (`targets: auto`)."""
        try:
            pairs = generated_targets(self.seed, self.style, self.rooms, **_table(self.table))
        except AvsError as exc:
            raise where.error(f"world seed {self.seed}: {exc}") from None
        return [Wanted(label, EXPECTED[not present]) for label, present in pairs]

    def labels(self, where: Where) -> list[tuple[str, int]]:
        """The labels the building holds with their instance counts, in the building's own
        order (sorted, then shuffled by `random.Random(seed)`: see the module's doc)."""
        try:
            counts = generated_instances(self.seed, self.style, self.rooms, **_table(self.table))
        except AvsError as exc:
            raise where.error(f"world seed {self.seed}: {exc}") from None
        ordered = sorted(label for label, n in counts.items() if n > 0)
        random.Random(self.seed).shuffle(ordered)
        return [(label, counts[label]) for label in ordered]

    def name(self) -> str:
        return generated_name(self.seed, self.style, self.rooms, self.table)


def generated_name(seed: int, style: str, rooms: int | None, table: str = DEFAULT_TABLE
                   ) -> str:
    from avs_planner.harness.worlds import generated_name as name

    return name(seed, style, rooms, table)


def generated_targets(seed: int, style: str, rooms: int | None, **table: str
                      ) -> list[tuple[str, bool]]:
    """The generator's (label, present in the world) targets for one generated world (`table`:
    of another placement table than the default)."""
    from avs_planner.harness.worlds import generated_targets as targets

    try:
        return list(targets(seed, style, rooms, **table))
    except ImportError as exc:
        raise CampaignError(f"generated worlds are not available in this build: {exc}") from None


def generated_instances(seed: int, style: str, rooms: int | None, **days: Any
                        ) -> dict[str, int]:
    """How many objects of each label one generated world holds (the generator's record); of
    a later day of it when `days` (day, move, doors) say so."""
    return dict(_instances(seed, style, rooms, tuple(sorted(days.items()))))


@cache
def _instances(seed: int, style: str, rooms: int | None, days: tuple[tuple[str, Any], ...]
               ) -> tuple[tuple[str, int], ...]:
    from avs_planner.harness.worlds import generated_instances as instances

    try:
        return tuple(instances(seed, style, rooms, **dict(days)).items())
    except ImportError as exc:
        raise CampaignError(f"generated worlds are not available in this build: {exc}") from None
