"""What a campaign searches: (world, target, start) subjects from scenarios or worlds × targets.

A subject carries the outcome to expect: a scenario's own; for a world file, `found` when
the world holds an object (or furniture) with the target's label, else `gave_up`; for a
generated world with `targets: auto`, the generator's (label, present) list.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from avs_planner.errors import AvsError
from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.values import Where, parse_seeds

AUTO = "auto"
_WORLD_KEYS = {"world", "generate", "targets", "start_room", "start"}
_GENERATE_KEYS = {"seeds", "style", "rooms"}
_TARGET_KEYS = {"label", "expected"}
_EXPECTED = ("found", "gave_up")


@dataclass(frozen=True)
class Subject:
    """A world, a target label and a start: the part of an episode a campaign varies least."""

    world: str  # display name
    group: str  # scenario name, world name or generator group: a row of the report
    target: str
    expected: str | None  # found / gave_up / None (unknown)
    scenario: str | None
    spec: Mapping[str, Any]  # episode keys: world or generate, start, start_room, ...


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
    if isinstance(top, dict):
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
    if value == AUTO:
        raise t_at.error("'auto' targets are for generated worlds; list labels instead")
    spec = {"world": ref, **{k: entry[k] for k in ("start", "start_room") if k in entry}}
    name = Path(text).stem
    for label, expected in _labels(value, t_at):
        yield Subject(name, name, label, expected or _EXPECTED[label not in labels], None,
                      spec)


def _generated(entry: dict[str, Any], targets: tuple[Any, Where], at: Where
               ) -> Iterator[Subject]:
    gen = entry["generate"]
    g_at = at.at("generate")
    if not isinstance(gen, dict) or "seeds" not in gen or set(gen) - _GENERATE_KEYS:
        raise g_at.error(f"a mapping with 'seeds' and optionally 'style', 'rooms' (keys "
                         f"{sorted(_GENERATE_KEYS)})")
    style, rooms = gen.get("style", "office"), gen.get("rooms")
    if not isinstance(style, str):
        raise g_at.at("style").error(f"a world style name, got {style!r}")
    if rooms is not None and (isinstance(rooms, bool) or not isinstance(rooms, int)
                              or rooms < 1):
        raise g_at.at("rooms").error(f"a positive number of rooms, got {rooms!r}")
    group = f"gen-{style}" + (f"-r{rooms}" if rooms is not None else "")
    value, t_at = targets
    for seed in parse_seeds(gen["seeds"], g_at.at("seeds")):
        spec = {"generate": {"seed": seed, "style": style, "rooms": rooms}}
        pairs = (_auto(seed, style, rooms, t_at) if value == AUTO
                 else list(_labels(value, t_at)))
        name = generated_name(seed, style, rooms)
        for label, expected in pairs:
            yield Subject(name, group, label, expected, None, spec)


def _auto(seed: int, style: str, rooms: int | None, where: Where
          ) -> list[tuple[str, str | None]]:
    try:
        pairs = generated_targets(seed, style, rooms)
    except AvsError as exc:
        raise where.error(f"world seed {seed}: {exc}") from None
    return [(label, _EXPECTED[not present]) for label, present in pairs]


def generated_name(seed: int, style: str, rooms: int | None) -> str:
    from avs_planner.harness.worlds import generated_name as name

    return name(seed, style, rooms)


def generated_targets(seed: int, style: str, rooms: int | None) -> list[tuple[str, bool]]:
    """The generator's (label, present in the world) targets for one generated world."""
    from avs_planner.harness.worlds import generated_targets as targets

    try:
        return list(targets(seed, style, rooms))
    except ImportError as exc:
        raise CampaignError(f"generated worlds are not available in this build: {exc}") from None


def _labels(value: Any, where: Where) -> Iterator[tuple[str, str | None]]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value:
        raise where.error(f"a non-empty list of labels (or 'auto'), got {value!r}")
    for i, item in enumerate(value):
        yield _label(item, where.at(i))


def _label(item: Any, where: Where) -> tuple[str, str | None]:
    if isinstance(item, str) and item and item != AUTO:
        return _known(item, where), None
    if not isinstance(item, dict) or not isinstance(item.get("label"), str):
        raise where.error(f"a label or {{label, expected}}, got {item!r}")
    if set(item) - _TARGET_KEYS:
        raise where.error(f"unknown keys {sorted(set(item) - _TARGET_KEYS)}")
    expected = item.get("expected")
    if expected is not None and expected not in _EXPECTED:
        raise where.at("expected").error(f"found or gave_up, got {expected!r}")
    return _known(item["label"], where.at("label")), expected


def _known(label: str, where: Where) -> str:
    """A label the robot's knowledge has priors for (else no strategy can search for it)."""
    labels = _knowledge_labels()
    if label not in labels:
        raise where.error(f"unknown target label {label!r}; the knowledge knows "
                          f"{', '.join(sorted(labels))}")
    return label


@cache
def _knowledge_labels() -> frozenset[str]:
    from conceptual_map.knowledge.loader import load_knowledge

    return frozenset(load_knowledge().labels)
