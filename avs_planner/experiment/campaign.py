"""Campaign files: which episodes to run, validated with errors that name the entry.

A campaign is worlds (or the active visual search paper's scenarios) × targets × strategies ×
robots × seeds, where a target is one label or a task of several objects (`subjects.py`); the
format is in docs/experiments.md. `load_campaign` reads and checks a file
(or a built-in by name, from `campaigns/`), and `Campaign.runs()` expands it into one `RunSpec`
per episode, each with a stable run id (the name of its directory in the output). A campaign
with `sequence` (`sequences.py`) runs each generated building's tasks day after day, with and
without the robot's memory; its runs carry their sequence, task index and memory arm. A
campaign with `experience` (`priors.py`) trains the experience store of learned priors (every
episode adds to it) or reads it: with `priors: [default, learned]`, each episode runs once on
the knowledge file alone and once on the store's priors, its runs carrying the arm.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from avs_planner.errors import AvsError
from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.priors import Experience, parse_experience, parse_priors
from avs_planner.experiment.sequences import Arm, Sequence, parse_sequence
from avs_planner.experiment.subjects import (
    Subject,
    scenario_subjects,
    sequence_subjects,
    world_subjects,
)
from avs_planner.experiment.values import Where, parse_seeds, positive_number

CAMPAIGN_DIR = Path(__file__).parent / "campaigns"
DEFAULT_STRATEGY = "switching"
# The evaluation-only seeds (docs/experiments.md, "Held-out seeds"): nothing is tuned on them.
HELDOUT_WORLD_SEEDS_FROM = 10000  # generated building seeds from here on
HELDOUT_FIG3_NOISE_SEEDS = range(100, 120)  # sensor-noise seeds of Fig. 3 a-f
_TOP_KEYS = {"name", "description", "worlds", "scenarios", "targets", "strategies", "robots",
             "seeds", "time_budget_s", "wall_budget_s", "sequence", "experience", "priors"}
_STRATEGY_KEYS = {"name", "label", "options"}


@dataclass(frozen=True)
class Strategy:
    """A registered strategy under a label (the same strategy may run with other options)."""

    label: str
    name: str
    options: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class RunSpec:
    """One episode of a campaign: what it searches, how, and where its files go."""

    run_id: str
    subject: Subject
    strategy: Strategy
    robot: str | None
    seed: int
    episode: Mapping[str, Any]
    # a task of a campaign sequence: the sequence's id, the task's index in it (its day) and
    # the memory arm (on / off); "" / None otherwise
    sequence: str = ""
    task_index: int | None = None
    memory: str = ""
    priors: str = ""  # a campaign with `priors`: the arm (default / learned); "" otherwise

    def columns(self) -> dict[str, Any]:
        """The run's coordinates as results-table columns."""
        s = self.subject
        return {"run_id": self.run_id, "scenario": s.scenario or "", "world": s.world,
                "group": s.group, "target": s.target, "expected": s.expected or "",
                "strategy": self.strategy.label, "robot": self.robot or "", "seed": self.seed,
                "task": s.kind, "task_labels": " ".join(s.labels) if s.task else "",
                "sequence": self.sequence, "task_index": self.task_index,
                "memory": self.memory, "priors": self.priors}


@dataclass(frozen=True)
class Campaign:
    """A validated campaign; `runs()` is the list of its episodes, in a fixed order."""

    name: str
    description: str
    source: str
    subjects: tuple[Subject, ...]
    strategies: tuple[Strategy, ...]
    robots: tuple[str | None, ...]
    seeds: tuple[int, ...]
    time_budget_s: float | None = None
    wall_budget_s: float | None = None
    sequence: Sequence | None = None
    experience: Experience | None = None  # the experience store its episodes use, if any
    priors: tuple[str, ...] = ()  # arms: default (no store) and learned (the store, read)

    def runs(self) -> list[RunSpec]:
        runs: list[RunSpec] = []
        if self.sequence is not None:
            runs = self._sequence_runs(self.sequence)
            _check_unique(runs, self.source)
            return runs
        for seed in self.seeds:
            for subject in self.subjects:
                for robot in self.robots:
                    for strategy in self.strategies:
                        run = self._run(subject, strategy, robot, seed)
                        if self.priors:
                            runs += [self._arm(run, arm) for arm in self.priors]
                        else:
                            runs.append(self._with_store(run))
        _check_unique(runs, self.source)
        return runs

    def _with_store(self, run: RunSpec) -> RunSpec:
        """The run with the campaign's experience store (and its world as the building)."""
        if self.experience is None:
            return run
        episode = {**run.episode, **self.experience.episode_keys(run.subject.world)}
        return dataclasses.replace(run, episode=episode)

    def _arm(self, run: RunSpec, arm: str) -> RunSpec:
        """The run in one arm of `priors`: `learned` reads the store, `default` has none."""
        if arm == "learned":
            run = self._with_store(run)
        return dataclasses.replace(run, run_id=_slug(f"{run.run_id}-priors-{arm}"), priors=arm)

    def _run(self, subject: Subject, strategy: Strategy, robot: str | None, seed: int
             ) -> RunSpec:
        spec: dict[str, Any] = {**subject.spec, **subject.episode_keys(), "seed": seed}
        if strategy.name != DEFAULT_STRATEGY or strategy.options:
            spec["strategy"] = strategy.name
            spec["strategy_options"] = dict(strategy.options)
        if robot is not None:
            spec["robot"] = robot
        for key in ("time_budget_s", "wall_budget_s"):
            if getattr(self, key) is not None:
                spec[key] = getattr(self, key)
        parts = [subject.scenario or subject.world]
        if subject.scenario is None:
            parts.append(subject.target)
        parts += [strategy.label, robot or "", f"s{seed}"]
        return RunSpec(_slug("-".join(p for p in parts if p)), subject, strategy, robot, seed,
                       spec)

    def _sequence_runs(self, sequence: Sequence) -> list[RunSpec]:
        """Per building, noise seed, robot, strategy and memory arm, one sequence: its tasks
        in order (task i on day i), each run carrying the sequence's id, its index and the
        arm; with memory on, the episode spec names the sequence's memory directory."""
        buildings: dict[str, list[Subject]] = {}
        for subject in self.subjects:
            buildings.setdefault(subject.world, []).append(subject)
        runs: list[RunSpec] = []
        for seed in self.seeds:
            for building, tasks in buildings.items():
                for robot in self.robots:
                    for strategy in self.strategies:
                        for memory in sequence.memory:
                            arm = Arm(building, robot, strategy.label, seed, memory)
                            runs += [self._task_run(s, strategy, robot, seed, arm, sequence)
                                     for s in sorted(tasks, key=lambda s: s.day or 0)]
        return runs

    def _task_run(self, subject: Subject, strategy: Strategy, robot: str | None, seed: int,
                  arm: Arm, sequence: Sequence) -> RunSpec:
        run = self._run(subject, strategy, robot, seed)
        episode = dict(run.episode)
        if arm.memory_dir is not None:
            episode.update(memory=arm.memory_dir, since_s=sequence.since_s)
        index = subject.day or 0
        parts = [subject.world, f"t{index:02d}", subject.target, strategy.label, robot or "",
                 f"s{seed}", f"memory-{arm.memory}"]
        return dataclasses.replace(run, run_id=_slug("-".join(p for p in parts if p)),
                                   episode=episode, sequence=_slug(arm.sequence_id),
                                   task_index=index, memory=arm.memory)


def builtin_campaigns() -> list[str]:
    return sorted(p.stem for p in CAMPAIGN_DIR.glob("*.yaml"))


def load_campaign(name_or_path: str | Path) -> Campaign:
    """A built-in campaign by name (e.g. `seed003-fig3`) or a campaign YAML file."""
    path = Path(name_or_path)
    if not path.exists() and not path.suffix:
        path = CAMPAIGN_DIR / f"{name_or_path}.yaml"
        if not path.exists():
            raise CampaignError(f"unknown campaign {str(name_or_path)!r}: not a file, and the "
                                f"built-in campaigns are {', '.join(builtin_campaigns())}")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise CampaignError(f"{path}: cannot read campaign: {exc}") from None
    return parse_campaign(data, str(path), path.parent)


def parse_campaign(data: Any, source: str, base: Path) -> Campaign:
    """Validate campaign data (as read from YAML); `base` resolves relative world paths."""
    where = Where(source)
    if not isinstance(data, dict):
        raise where.error("a campaign is a mapping (name, worlds or scenarios, targets, ...)")
    unknown = set(data) - _TOP_KEYS
    if unknown:
        raise where.error(f"unknown keys {sorted(unknown)}; allowed: {sorted(_TOP_KEYS)}")
    sequence = None
    if "sequence" in data:
        sequence = parse_sequence(data["sequence"], where.at("sequence"))
    experience, priors = _experience(data, where, sequence)
    return Campaign(
        name=str(data.get("name") or Path(source).stem),
        description=str(data.get("description") or ""), source=source,
        subjects=_subjects(data, where, base, sequence),
        strategies=_strategies(data.get("strategies", [DEFAULT_STRATEGY]), where.at("strategies")),
        robots=_robots(data.get("robots"), where.at("robots")),
        seeds=tuple(parse_seeds(data.get("seeds", 0), where.at("seeds"))),
        time_budget_s=_budget(data, "time_budget_s", where),
        wall_budget_s=_budget(data, "wall_budget_s", where),
        sequence=sequence, experience=experience, priors=priors,
    )


def _experience(data: dict[str, Any], where: Where, sequence: Sequence | None
                ) -> tuple[Experience | None, tuple[str, ...]]:
    """The campaign's `experience` and `priors` (`priors.py`); not with `sequence`."""
    for key in ("experience", "priors"):
        if key in data and sequence is not None:
            raise where.at(key).error("not with 'sequence' (a campaign sequence runs with its "
                                      "memory on and off; learned priors are measured on "
                                      "campaigns of worlds and targets)")
    experience = None
    if "experience" in data:
        experience = parse_experience(data["experience"], where.at("experience"))
    priors: tuple[str, ...] = ()
    if "priors" in data:
        priors = parse_priors(data["priors"], experience, where.at("priors"),
                              where.at("experience"))
    return experience, priors


def _subjects(data: dict[str, Any], where: Where, base: Path, sequence: Sequence | None
              ) -> tuple[Subject, ...]:
    has_worlds, has_scenarios = "worlds" in data, "scenarios" in data
    if sequence is not None:
        if has_scenarios or not has_worlds:
            raise where.at("sequence").error("a sequence runs on generated buildings: give "
                                             "'worlds' with {generate: {seeds, style}} "
                                             "entries, not 'scenarios'")
        if "targets" in data:
            raise where.at("targets").error("a sequence draws each task's target from the "
                                            "labels its building holds that day; drop "
                                            "'targets'")
        return tuple(sequence_subjects(data["worlds"], sequence, where))
    if has_worlds == has_scenarios:
        raise where.error("give either 'worlds' (with 'targets') or 'scenarios', not both")
    if has_scenarios:
        if "targets" in data:
            raise where.at("targets").error("scenarios bring their own targets; drop 'targets'")
        return tuple(scenario_subjects(data["scenarios"], where.at("scenarios"), base))
    return tuple(world_subjects(data["worlds"], data.get("targets"), where, base))


def _strategies(value: Any, where: Where) -> tuple[Strategy, ...]:
    if isinstance(value, str):
        value = [value]
    if isinstance(value, dict):  # {name: options}
        value = [{"name": k, "options": v or {}} for k, v in value.items()]
    if not isinstance(value, list) or not value:
        raise where.error("a non-empty list of strategy names or {name, label, options}")
    known = strategy_names()
    strategies = [_strategy(item, where.at(i), known) for i, item in enumerate(value)]
    labels = [s.label for s in strategies]
    for i, label in enumerate(labels):
        if label in labels[:i]:
            raise where.at(i).error(f"label {label!r} is used twice; give each entry a "
                                    "distinct 'label'")
    return tuple(strategies)


def _strategy(item: Any, where: Where, known: list[str]) -> Strategy:
    if isinstance(item, str):
        item = {"name": item}
    if not isinstance(item, dict) or "name" not in item:
        raise where.error("a strategy name or a mapping {name, label, options}")
    if set(item) - _STRATEGY_KEYS:
        raise where.error(f"unknown keys {sorted(set(item) - _STRATEGY_KEYS)}; allowed: "
                          f"{sorted(_STRATEGY_KEYS)}")
    name = item["name"]
    if name not in known:
        raise where.error(f"unknown strategy {name!r}; known strategies: {', '.join(known)}")
    options = item.get("options") or {}
    if not isinstance(options, dict):
        raise where.at("options").error("strategy options are a mapping")
    _check_options(name, options, where.at("options"))
    label = str(item.get("label") or name)
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", label):
        raise where.at("label").error(f"{label!r}: use letters, digits, '-', '_' or '.'")
    return Strategy(label, name, options)


def strategy_names() -> list[str]:
    """The registered strategies."""
    from avs_planner.strategies import strategy_names as registered

    return list(registered())


def _check_options(name: str, options: dict[str, Any], where: Where) -> None:
    """The strategy's own check of its options (names and types), at load time."""
    from avs_planner.strategies import get_strategy

    try:
        get_strategy(name).check_options(options)
    except AvsError as exc:
        raise where.error(str(exc)) from None


def _robots(value: Any, where: Where) -> tuple[str | None, ...]:
    if value is None:
        return (None,)  # each world's own robot
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value:
        raise where.error("a non-empty list of robot models")
    from avs_planner.harness.sim_robot import ROBOT_MODELS

    for i, robot in enumerate(value):
        if robot not in ROBOT_MODELS:
            raise where.at(i).error(f"unknown robot {robot!r}; known: "
                                    f"{', '.join(sorted(ROBOT_MODELS))}")
    return tuple(value)


def _budget(data: dict[str, Any], key: str, where: Where) -> float | None:
    if key not in data:
        return None
    return positive_number(data[key], where.at(key))


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9_.]+", "-", text.lower()).strip("-")


def _check_unique(runs: list[RunSpec], source: str) -> None:
    seen: dict[str, RunSpec] = {}
    for run in runs:
        other = seen.setdefault(run.run_id, run)
        if other is not run:
            raise CampaignError(f"{source}: two runs would share the id {run.run_id!r} "
                                f"(world {run.subject.world!r} listed twice?)")
