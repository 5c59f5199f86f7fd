"""State, action and observation of the view-cone search POMDP (§2 "DT planner" of the active
visual search paper by Göbelbecker et al.).

The robot stands at the start pose or at one view cone's pose; the target is in one cone or in
none of them. Robot position, the last detection flag and `done` are observed; only the target is
hidden, so a belief is a distribution over `n + 1` targets. What a session is given (the view
cones, the detector model) is in `inputs.py`, which needs no pomdp-py.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from functools import cache

import pomdp_py

START = -1
"""Robot index of the start pose (no view cone)."""
NOWHERE = -1
"""Target index meaning "the object is in none of the cones"."""


@dataclass(frozen=True)
class DTState(pomdp_py.State):
    """Robot cone index (START), target cone index (NOWHERE), last look detected?, finished?"""

    robot: int
    target: int
    detected: bool = False
    done: bool = False
    _hash: int = field(init=False, repr=False, compare=False, default=0)

    def __post_init__(self) -> None:  # planners hash states constantly: compute once
        object.__setattr__(self, "_hash", hash((self.robot, self.target, self.detected,
                                                self.done)))

    def __hash__(self) -> int:
        return self._hash


class ActionKind(Enum):
    MOVE = "move"
    PROCESS_VIEW_CONE = "process_view_cone"
    CONFIRM = "confirm"
    REJECT = "reject"


@dataclass(frozen=True)
class DTAction(pomdp_py.Action):
    """MOVE(cone), PROCESSVIEWCONE(cone the robot is at), CONFIRM(cone), REJECT."""

    kind: ActionKind
    cone: int = -1
    _hash: int = field(init=False, repr=False, compare=False, default=0)

    def __post_init__(self) -> None:  # POUCT hashes actions in every UCB step
        object.__setattr__(self, "_hash", hash((self.kind.value, self.cone)))

    def __hash__(self) -> int:
        return self._hash

    @property
    def terminal(self) -> bool:
        return self.kind in (ActionKind.CONFIRM, ActionKind.REJECT)

    def __str__(self) -> str:
        return self.kind.value if self.cone < 0 else f"{self.kind.value}({self.cone})"


@cache
def move(cone: int) -> DTAction:
    return DTAction(ActionKind.MOVE, cone)


@cache
def look(cone: int) -> DTAction:
    return DTAction(ActionKind.PROCESS_VIEW_CONE, cone)


@cache
def confirm(cone: int) -> DTAction:
    return DTAction(ActionKind.CONFIRM, cone)


REJECT = DTAction(ActionKind.REJECT)


class ObservationKind(Enum):
    NOTHING = "nothing"  # actions that do not sense
    DETECTED = "detected"
    NOT_DETECTED = "not_detected"


@dataclass(frozen=True)
class DTObservation(pomdp_py.Observation):
    """What PROCESSVIEWCONE reported; NOTHING after other actions."""

    kind: ObservationKind = ObservationKind.NOTHING

    def __hash__(self) -> int:
        return hash(self.kind.value)

    @staticmethod
    def of(detected: bool) -> DTObservation:
        return DETECTED if detected else NOT_DETECTED


NOTHING = DTObservation(ObservationKind.NOTHING)
DETECTED = DTObservation(ObservationKind.DETECTED)
NOT_DETECTED = DTObservation(ObservationKind.NOT_DETECTED)
