"""The six office runs (Fig. 3 a-f) of the active visual search paper as scenario files: an
episode spec plus the outcome the paper reports. Built-ins live in `scenarios/`; any YAML path
works too."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from avs_planner.episode.errors import EpisodeError

SCENARIO_DIR = Path(__file__).parent / "scenarios"
_SPEC_KEYS = {"world", "target", "category", "robot", "start_room", "start", "seed",
              "time_budget_s", "pre_explore"}


@dataclass(frozen=True)
class Scenario:
    name: str
    description: str
    expected: str  # found / gave_up
    spec: dict[str, Any]

    def episode_spec(self, **overrides: Any) -> dict[str, Any]:
        return {**self.spec, **{k: v for k, v in overrides.items() if v is not None}}


def builtin_scenarios() -> list[str]:
    return sorted(p.stem for p in SCENARIO_DIR.glob("*.yaml"))


def load_scenario(name_or_path: str | Path) -> Scenario:
    """A built-in scenario by name (`a` ... `f`) or a scenario YAML file."""
    path = Path(name_or_path)
    if not path.suffix:
        path = SCENARIO_DIR / f"{name_or_path}.yaml"
        if not path.exists():
            raise EpisodeError(f"unknown scenario {name_or_path!r}; built-in: "
                               f"{', '.join(builtin_scenarios())}")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise EpisodeError(f"{path}: cannot read scenario: {exc}") from exc
    if not isinstance(data, dict):
        raise EpisodeError(f"{path}: a scenario is a mapping")
    spec = data.get("episode")
    if not isinstance(spec, dict) or set(spec) - _SPEC_KEYS:
        raise EpisodeError(f"{path}: 'episode' must be a mapping with keys from "
                           f"{sorted(_SPEC_KEYS)}")
    if data.get("expected") not in ("found", "gave_up"):
        raise EpisodeError(f"{path}: 'expected' must be found or gave_up")
    world = spec.get("world", "office")
    if isinstance(world, str) and world.endswith(".yaml") and not Path(world).is_absolute():
        spec = {**spec, "world": str((path.parent / world).resolve())}
    return Scenario(str(data.get("name", path.stem)), str(data.get("description", "")),
                    data["expected"], spec)
