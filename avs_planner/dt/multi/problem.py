"""The input of one multi-label DT call: shared view cones, travel and sensing cost; per label
its prior over the cones, its detector and its terminal penalties.

Every label is also kept as a single-label `DTProblem` over the same cones (`single(i)`), so the
single-label belief, stop rule and validation serve each label unchanged: the labels
share the robot and its looks, nothing else.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

from avs_planner.dt.errors import DtInputError
from avs_planner.dt.inputs import DetectorModel, ViewCone
from avs_planner.dt.multi.domain import SearchMode
from avs_planner.dt.problem import DTProblem, DTRewards, TravelCosts


@dataclass(frozen=True)
class LabelTarget:
    """One label to find: P(label in cone i) per cone (the problem's cone order; the rest of
    the mass is "in none of them"), its detector and its terminal penalties."""

    label: str
    probabilities: tuple[float, ...]
    detector: DetectorModel = field(default_factory=DetectorModel)
    rewards: DTRewards = field(default_factory=DTRewards)

    def __post_init__(self) -> None:
        object.__setattr__(self, "probabilities", tuple(float(p) for p in self.probabilities))


def _mode(mode: SearchMode | str) -> SearchMode:
    if isinstance(mode, SearchMode):
        return mode
    try:
        return SearchMode(mode)
    except ValueError:
        choices = [m.value for m in SearchMode]
        raise DtInputError(f"search mode {mode!r} is not one of {choices}") from None


@dataclass(frozen=True)
class MultiLabelProblem:
    """A validated multi-label view-cone search. The cones' own `probability` is not used:
    each label's prior is its `LabelTarget.probabilities`. `horizon` bounds the MOVE and
    PROCESSVIEWCONE actions (CONFIRM/REJECT are free)."""

    cones: tuple[ViewCone, ...]
    targets: tuple[LabelTarget, ...]
    travel: TravelCosts
    sensing_cost: float = 1.0
    mode: SearchMode = SearchMode.ALL
    horizon: int = 0  # 0: 2 * (cones some label may be in) + 4, as the single-label default
    _singles: tuple[DTProblem, ...] = field(init=False, repr=False, compare=False, default=())
    _relevant: dict[tuple[int, ...], tuple[int, ...]] = field(
        init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "cones", tuple(self.cones))
        object.__setattr__(self, "targets", tuple(self.targets))
        object.__setattr__(self, "mode", _mode(self.mode))
        self._check_labels()
        if self.horizon < 0:
            raise DtInputError(f"horizon {self.horizon} must be >= 0")
        if self.horizon == 0:
            relevant = {i for t in self.targets for i, p in enumerate(t.probabilities) if p > 0}
            object.__setattr__(self, "horizon", 2 * len(relevant) + 4)
        object.__setattr__(self, "_singles", tuple(self._single_problem(t)
                                                   for t in self.targets))

    def _check_labels(self) -> None:
        if not self.targets:
            raise DtInputError("multi-label DT: no labels to search for")
        seen: set[str] = set()
        for i, target in enumerate(self.targets):
            if not target.label:
                raise DtInputError(f"label {i}: the label name is empty")
            if target.label in seen:
                raise DtInputError(f"label {i}: duplicate label {target.label!r}")
            seen.add(target.label)
            if len(target.probabilities) != len(self.cones):
                raise DtInputError(
                    f"label {target.label!r}: {len(target.probabilities)} probabilities for "
                    f"{len(self.cones)} view cones")

    def _single_problem(self, target: LabelTarget) -> DTProblem:
        cones = tuple(dataclasses.replace(c, probability=p)
                      for c, p in zip(self.cones, target.probabilities, strict=True))
        try:
            return DTProblem(cones, self.travel, target.detector, self.sensing_cost,
                             target.rewards, self.horizon)
        except DtInputError as error:
            raise DtInputError(f"label {target.label!r}: {error}") from error

    @property
    def n(self) -> int:
        """Number of view cones."""
        return len(self.cones)

    @property
    def k(self) -> int:
        """Number of labels."""
        return len(self.targets)

    @cached_property
    def labels(self) -> tuple[str, ...]:
        return tuple(t.label for t in self.targets)

    @cached_property
    def _index(self) -> dict[str, int]:
        return {label: i for i, label in enumerate(self.labels)}

    def index(self, label: str) -> int:
        """Position of `label` in the problem; DtInputError if it is not one of them."""
        i = self._index.get(label)
        if i is None:
            raise DtInputError(f"unknown label {label!r}; the labels are {list(self.labels)}")
        return i

    def single(self, i: int) -> DTProblem:
        """Label `i` as a single-label problem (same cones, travel, sensing and horizon)."""
        return self._singles[i]

    @property
    def singles(self) -> tuple[DTProblem, ...]:
        return self._singles

    def relevant_cones(self, labels: Sequence[int]) -> tuple[int, ...]:
        """Cones that may hold one of `labels` (prior > 0), in cone order."""
        key = tuple(labels)
        cones = self._relevant.get(key)
        if cones is None:
            cones = tuple(sorted({c for i in key for c in self._singles[i].relevant_cones}))
            self._relevant[key] = cones
        return cones

    @property
    def metric(self) -> bool:
        """True if no detour through another cone is cheaper than the direct move."""
        return self._singles[0].metric

    def travel_cost(self, robot: int, cone: int) -> float:
        """Cost to move from robot position (START or a cone index) to `cone`."""
        return self._singles[0].travel_cost(robot, cone)

    @cached_property
    def inverse_look_costs(self) -> tuple[tuple[float, ...], ...]:
        """Per robot position (START last): 1 / (travel + sensing) to each cone, for the
        utility "expected penalty removed per second"."""
        rows = [*range(self.n), -1]
        return tuple(tuple(1.0 / max(self.travel_cost(r, c) + self.sensing_cost, 1e-12)
                           for c in range(self.n)) for r in rows)
