"""State, action and observation of the view-cone search for several labels at once.

Each open label is in one view cone or in none, independently of the others; one look at a
cone reports, for every open label, whether the detector saw it. A label is closed by claiming
where it is: CONFIRM(label, cone) claims that cone, REJECT(label) claims "nowhere". The claims
are kept per label as ints: `OPEN`, `NOWHERE` (rejected) or the confirmed cone.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum

import pomdp_py

from avs_planner.dt.domain import NOTHING, ActionKind, DTObservation

OPEN = -2
"""Claim of a label still searched for (NOWHERE, -1, is a rejection; >= 0 a confirmed cone)."""


class SearchMode(Enum):
    """When the search ends: every label decided ("all") or the first confirmed ("any")."""

    ALL = "all"
    ANY = "any"


def finished(claims: Sequence[int], mode: SearchMode) -> bool:
    """True once every label is decided, or (mode ANY) once one is confirmed."""
    if mode is SearchMode.ANY and any(c >= 0 for c in claims):
        return True
    return OPEN not in claims


@dataclass(frozen=True, eq=False)
class MultiAction(pomdp_py.Action):
    """MOVE(cone), PROCESSVIEWCONE(cone), CONFIRM(label, cone), REJECT(label).

    `label` is the label the action serves. For CONFIRM/REJECT it is part of the action; on a
    MOVE/LOOK it only reports which label's expected value chose it (None if no one label did)
    and is ignored by equality and hashing, so the same move chosen for another reason is
    still the same action."""

    kind: ActionKind
    cone: int = -1
    label: str | None = None
    _key: tuple = field(init=False, repr=False, default=())

    def __post_init__(self) -> None:
        who = self.label if self.terminal else None
        object.__setattr__(self, "_key", (self.kind.value, self.cone, who))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, MultiAction) and self._key == other._key

    def __hash__(self) -> int:
        return hash(self._key)

    @property
    def terminal(self) -> bool:
        """CONFIRM/REJECT: closes one label (and the search, once `finished`)."""
        return self.kind in (ActionKind.CONFIRM, ActionKind.REJECT)

    def __str__(self) -> str:
        args = [str(self.cone)] if self.cone >= 0 else []
        if self.label is not None:
            args.insert(0, self.label)
        return f"{self.kind.value}({', '.join(args)})" if args else self.kind.value


def move_to(cone: int, label: str | None = None) -> MultiAction:
    return MultiAction(ActionKind.MOVE, cone, label)


def look_at(cone: int, label: str | None = None) -> MultiAction:
    return MultiAction(ActionKind.PROCESS_VIEW_CONE, cone, label)


def confirm_label(label: str, cone: int) -> MultiAction:
    return MultiAction(ActionKind.CONFIRM, cone, label)


def reject_label(label: str) -> MultiAction:
    return MultiAction(ActionKind.REJECT, -1, label)


@dataclass(frozen=True)
class MultiObservation(pomdp_py.Observation):
    """Per label (problem order): DETECTED / NOT_DETECTED after a look, NOTHING otherwise and
    for labels already decided."""

    per_label: tuple[DTObservation, ...]

    def __hash__(self) -> int:
        return hash(tuple(o.kind.value for o in self.per_label))

    @staticmethod
    def nothing(labels: int) -> MultiObservation:
        return MultiObservation((NOTHING,) * labels)


@dataclass(frozen=True)
class MultiLabelState(pomdp_py.State):
    """Robot cone (START), per label: target cone (NOWHERE), last look detected it?, claim;
    `done` once the search is finished."""

    robot: int
    targets: tuple[int, ...]
    detected: tuple[bool, ...]
    claims: tuple[int, ...]
    done: bool = False
    _hash: int = field(init=False, repr=False, compare=False, default=0)

    def __post_init__(self) -> None:  # planners hash states constantly: compute once
        object.__setattr__(self, "_hash", hash((self.robot, self.targets, self.detected,
                                                self.claims, self.done)))

    def __hash__(self) -> int:
        return self._hash

    @classmethod
    def start(cls, robot: int, targets: Sequence[int]) -> MultiLabelState:
        """Every label open, nothing detected."""
        k = len(targets)
        return cls(robot, tuple(targets), (False,) * k, (OPEN,) * k)

