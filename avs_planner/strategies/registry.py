"""The registry: strategy name -> where its `run` function lives, what it does, its options."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.outcome import SearchResult
from avs_planner.errors import AvsError
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.qsr_options import OPTIONS as _QSR_OPTIONS
from avs_planner.strategies.qsr_options import REMOVED as _QSR_REMOVED
from avs_planner.strategies.switching.loop import LoopConfig

_QSR_CHECK = "avs_planner.strategies.qsr_options:check_options"

Run = Callable[[SearchContext], SearchResult]


class StrategyError(EpisodeError):
    """An unknown strategy name or a bad strategy option."""


@dataclass(frozen=True)
class Strategy:
    """A registered strategy: `entry` is "module:function"; `options` name its settings and
    their defaults (types are taken from the defaults)."""

    name: str
    summary: str
    entry: str
    options: Mapping[str, Any]
    prepare: str | None = None  # "module:function" run by `pre_explore` instead of the plain
    # frontier exploration, before the clock starts (e.g. FLAP's survey with depth frames)
    check: str | None = None  # "module:function" checking the converted options further
    # (raises an AvsError naming the option)
    configure: str | None = None  # "module:function": checked options -> (ExecutorConfig,
    # BuilderConfig) the episode builds its executor and state builder with (None: defaults)
    removed: Mapping[str, str] = field(default_factory=dict)  # options it no longer takes ->
    # what to use instead (refused with that message)

    def load(self) -> Run:
        return _load(self.entry)

    def configs(self, options: Mapping[str, Any]) -> tuple[Any, Any]:
        """(ExecutorConfig, BuilderConfig) for checked `options` (None, None: the defaults)."""
        return _load(self.configure)(options) if self.configure else (None, None)

    def load_prepare(self) -> Callable[[SearchContext], None] | None:
        return _load(self.prepare) if self.prepare else None

    def check_options(self, given: Mapping[str, Any] | None) -> dict[str, Any]:
        """The defaults overridden by `given`, each converted to its default's type."""
        given = dict(given or {})
        for key in sorted(set(given) & set(self.removed)):
            raise StrategyError(f"strategy {self.name!r}: option {key!r} was removed: "
                                f"{self.removed[key]}")
        unknown = sorted(set(given) - set(self.options))
        if unknown:
            known = ", ".join(sorted(self.options)) or "none"
            raise StrategyError(f"strategy {self.name!r}: unknown option(s) "
                                f"{', '.join(unknown)} (known: {known})")
        options = {key: _convert(self.name, key, given.get(key, default), default)
                   for key, default in self.options.items()}
        if self.check:
            try:
                _load(self.check)(options)
            except AvsError as exc:
                raise StrategyError(f"strategy {self.name!r}: {exc}") from None
        return options


def _load(entry: str) -> Callable[..., Any]:
    module, function = entry.split(":")
    return getattr(importlib.import_module(module), function)


def _convert(strategy: str, key: str, value: Any, default: Any) -> Any:
    kind = type(default)
    if value is None or isinstance(value, kind) and not (kind is int and isinstance(value, bool)):
        return value
    try:
        if kind is bool:
            if isinstance(value, str) and value.lower() in ("true", "false", "1", "0"):
                return value.lower() in ("true", "1")
            raise ValueError
        if kind in (int, float) and not isinstance(value, bool):
            converted = kind(value)
            if kind is int and converted != float(value):
                raise ValueError
            return converted
        if kind is str:
            return str(value)
    except (TypeError, ValueError):
        pass
    raise StrategyError(f"strategy {strategy!r}: option {key!r} must be {_article(kind.__name__)} "
                        f"(default {default!r}), got {value!r}")


# the loop's settings, less what the episode spec gives (budgets, where to dump problems)
_SWITCHING_OPTIONS = {f.name: f.default for f in fields(LoopConfig)
                      if f.name not in ("time_budget_s", "wall_budget_s", "dump_dir")}
# the view cones of a search on a support: "cones" (2D, around it) or "flap" (FLAP's views in
# the 3D map; avs_planner/strategies/flap_views.py)
_SWITCHING_OPTIONS["views"] = "cones"
# QSR-weighted cones when QSRs are known for the target: on|off|observe (strategies/switching/)
_SWITCHING_OPTIONS["qsr_cones"] = "off"

_FLAP_OPTIONS = {  # avs_planner/strategies/flap.py
    "greedy": False,  # next best view by p/t (the FLAP paper's baseline), not branch and bound
    "views": 200,  # view samples per cycle (the views still planned count towards them)
    "clusters": 50,  # transition table clusters
    "time_limit_s": 0.5,  # planner wall limit per cycle (0: none); its first plan is greedy
    "omega": 0.05,  # give up once p(V̂(S)) < omega
    "p_volume": 0.2,  # P_i per support volume (FLAP paper: 0.2); <= 0: the conceptual map's
    # belief
    "prior_map": True,  # the preparation (pre_explore) builds the 3D map with depth frames
    "reset_region": True,  # forget the 3D map inside the search region at the start
    "support_reach": 0.7,  # m: half width of a support's box around its detected centre
    "volume_height": 0.3,  # m: height of a support's box above its top
    "depth_columns": 48,  # depth frame columns at a view (rows: 3/4 of them)
    "survey_headings": 6,  # headings looked at per survey stop
    "survey_on": True,  # after a region is searched, survey on for more supports
    "sense_en_route": True,  # drive to views with the executor (scans every metre, place
    # classification, the target watch); false: one path, no sensing on the way (as in the
    # FLAP paper)
    "max_views": 80,
    "volumes": [],  # the task's search region: [{lo: [x, y, z], hi: [x, y, z], p, name}, ...]
    # (the FLAP paper's experiments give the volumes); empty: boxes above the known supports
}

STRATEGIES: dict[str, Strategy] = {s.name: s for s in (
    Strategy("switching", "the switching planner: continual PDDL planner with assumptions + "
             "POMDP view-cone search (Goebelbecker et al.)",
             "avs_planner.strategies.switching:run", _SWITCHING_OPTIONS,
             check="avs_planner.strategies.switching:check_options",
             configure="avs_planner.strategies.switching:configure"),
    Strategy("exhaustive", "baseline: frontier exploration, nearest placeholder first, "
             "looking all round at every stop; no priors",
             "avs_planner.strategies.baselines:run_exhaustive",
             {"headings": 6, "max_stops": 400, "retry_blocked": 2}),
    Strategy("most-likely-room", "baseline: rooms in order of P(object in room), each swept "
             "fully; unexplored space competes as a hypothetical room",
             "avs_planner.strategies.baselines:run_most_likely_room",
             {"headings": 6, "sweep_spacing": 1.5, "max_stops": 400, "retry_blocked": 2}),
    Strategy("qsr", "indirect search (Kunze et al.): survey landmarks and supporting planes, "
             "then views where the QSR mixture (target relative to landmarks) is densest; "
             "abort after 120 s of search",
             "avs_planner.strategies.qsr:run_qsr", _QSR_OPTIONS,
             check=_QSR_CHECK, removed=_QSR_REMOVED),
    Strategy("supporting-planes", "QSR baseline: as qsr, views scored by a uniform density "
             "over the supporting planes",
             "avs_planner.strategies.qsr:run_supporting_planes", _QSR_OPTIONS,
             check=_QSR_CHECK, removed=_QSR_REMOVED),
    Strategy("random", "QSR baseline: as qsr, but a random one of the 20 sampled view poses",
             "avs_planner.strategies.qsr:run_random", _QSR_OPTIONS,
             check=_QSR_CHECK, removed=_QSR_REMOVED),
    Strategy("flap", "FLAP (Gedicke et al.): frontier view sampling in the 3D map and "
             "expected-time view sequencing over the target's known supports (greedy: true is "
             "its baseline)",
             "avs_planner.strategies.flap:run", _FLAP_OPTIONS,
             prepare="avs_planner.strategies.flap:prepare",
             check="avs_planner.strategies.flap:check_options"),
)}


def strategy_names() -> list[str]:
    return sorted(STRATEGIES)


def get_strategy(name: str) -> Strategy:
    strategy = STRATEGIES.get(name)
    if strategy is None:
        raise StrategyError(f"unknown strategy {name!r} (known: {', '.join(strategy_names())})")
    return strategy


def _article(noun: str) -> str:
    return f"an {noun}" if noun[0] in "aeiou" else f"a {noun}"
