"""Campaign sequences: one building's tasks, day after day, with and without the robot's memory.

A campaign with `sequence: {tasks: N, move: p, doors: q, since_s: s, memory: [on, off]}` runs,
for every generated building of its `worlds` (`{generate: {seeds, style, rooms}}` entries),
robot, strategy and noise seed, N episodes in order: task i on day i of the building
(`sim.generate`: each day small objects move with probability p and doors toggle with
probability q), its target one label the building holds that day, drawn by
`random.Random("<building seed>:<i>")` from the labels present (sorted), so every arm and
strategy searches for the same labels. Each arm of `memory` is a separate sequence: `on` gives
every episode `memory: <out>/memory/<building>-<robot>-<strategy>-s<seed>` and `since_s`
(the building memory reads it at the start and writes it at the end), `off` neither.

The episodes of one sequence run one after another (each reads the memory the one before
wrote): the runner hands a sequence to a worker slot as one unit (`runner.py`). The memory
path is written relative (`memory/...`) and placed under the campaign's output directory
when the campaign runs (`placed`).
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avs_planner.experiment.values import Where

SEQUENCE_KEYS = ("tasks", "move", "doors", "since_s", "memory")
MEMORY_ARMS = ("on", "off")
MEMORY_DIR = "memory"  # under the campaign's output directory
MAX_TASKS = 1000
DEFAULT_SINCE_S = 3600.0


@dataclass(frozen=True)
class Sequence:
    """A campaign's `sequence` entry, checked."""

    tasks: int
    move: float = 0.2
    doors: float = 0.0
    since_s: float = DEFAULT_SINCE_S
    memory: tuple[str, ...] = MEMORY_ARMS

    def generate(self, day: int) -> dict[str, Any]:
        """The `generate` keys of a task on `day`."""
        return {"day": day, "move": self.move, "doors": self.doors}


def parse_sequence(value: Any, where: Where) -> Sequence:
    """`{tasks, move, doors, since_s, memory}`; CampaignError naming the key."""
    if not isinstance(value, dict):
        raise where.error(f"a mapping {{tasks: N, move: p, doors: q, since_s: s, memory: "
                          f"[on, off]}}, got {value!r}")
    unknown = set(value) - set(SEQUENCE_KEYS)
    if unknown:
        raise where.error(f"unknown keys {sorted(unknown)}; allowed: {list(SEQUENCE_KEYS)}")
    if "tasks" not in value:
        raise where.at("tasks").error("required: the number of tasks in each sequence")
    tasks = value["tasks"]
    if isinstance(tasks, bool) or not isinstance(tasks, int) or not 1 <= tasks <= MAX_TASKS:
        raise where.at("tasks").error(f"a whole number of tasks from 1 to {MAX_TASKS}, got "
                                      f"{tasks!r}")
    move = _probability(value.get("move", 0.2), where.at("move"))
    doors = _probability(value.get("doors", 0.0), where.at("doors"))
    since = value.get("since_s", DEFAULT_SINCE_S)
    if isinstance(since, bool) or not isinstance(since, int | float) \
            or not math.isfinite(since) or since < 0:
        raise where.at("since_s").error(f"simulated seconds since the building's previous "
                                        f"task, a number >= 0; got {since!r}")
    return Sequence(tasks, move, doors, float(since),
                    _arms(value.get("memory", list(MEMORY_ARMS)), where.at("memory")))


def _probability(value: Any, where: Where) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not math.isfinite(value) or not 0.0 <= value <= 1.0:
        raise where.error(f"a probability in [0, 1], got {value!r}")
    return float(value)


def _arms(value: Any, where: Where) -> tuple[str, ...]:
    """`on`, `off` or a list of them (YAML reads a bare on / off as true / false)."""
    items = value if isinstance(value, list) else [value]
    arms = []
    for i, item in enumerate(items):
        arm = {True: "on", False: "off"}.get(item, item) if isinstance(item, bool) else item
        at = where.at(i) if isinstance(value, list) else where
        if arm not in MEMORY_ARMS:
            raise at.error(f"'on' or 'off', got {item!r}")
        if arm in arms:
            raise at.error(f"{arm!r} is listed twice")
        arms.append(arm)
    if not arms:
        raise where.error("a non-empty list of 'on' and 'off'")
    return tuple(arms)


def task_label(seed: int, index: int, labels: list[str]) -> str:
    """The target of task `index` of building `seed`: one of the labels present that day."""
    return random.Random(f"{seed}:{index}").choice(sorted(labels))


@dataclass(frozen=True)
class Arm:
    """One sequence's identity: what its run ids, column and memory directory are made of."""

    building: str
    robot: str | None
    strategy: str
    seed: int
    memory: str  # on / off

    @property
    def sequence_id(self) -> str:
        return "-".join(p for p in (self.building, self.strategy, self.robot or "",
                                    f"s{self.seed}", f"memory-{self.memory}") if p)

    @property
    def memory_dir(self) -> str | None:
        """The memory directory relative to the campaign's output (None without memory)."""
        if self.memory != "on":
            return None
        name = "-".join(p for p in (self.building, self.robot or "", self.strategy,
                                    f"s{self.seed}") if p)
        return f"{MEMORY_DIR}/{name}"


def placed(episode: dict[str, Any], out: Path) -> dict[str, Any]:
    """The episode spec with its memory directory placed under the output directory `out`."""
    memory = episode.get("memory")
    if memory is None or Path(memory).is_absolute():
        return episode
    return {**episode, "memory": str((out / memory).resolve())}


def ordered(items: list[Any], key: Any) -> Iterator[list[Any]]:
    """`items` grouped by `key(item)` (None: alone), groups in order of first appearance."""
    groups: dict[Any, list[Any]] = {}
    for i, item in enumerate(items):
        k = key(item)
        groups.setdefault(("alone", i) if k is None else k, []).append(item)
    yield from groups.values()


__all__ = ["MEMORY_ARMS", "SEQUENCE_KEYS", "Arm", "Sequence", "ordered", "parse_sequence",
           "placed", "task_label"]
