"""The view-cone skill: CREATEVIEWCONES, and the cone sets a later SEARCHFOROBJECT searches.

A cone set is made for (label, relation, location): round a known support (`on`: on it and
in it, where the knowledge puts the label) or over a room (`in`), weighted by the target's
P(ObjectAt) there under the plan's category assumption (`target_probability`). The 2D cones of
`episode/viewcones.py` are the default; a strategy may put in its own makers: support views
(`support_views`, the switching strategy's FLAP views) or QSR-weighted cones (`qsr_cones`,
`strategies/switching/qsr_cones.py`). Each set keeps the map's P(ObjectAt) of its location
when it was made, so a later search starts from what looks since then have left
(`ConeSets.now`).

`ConeSets` receives the executor's `SkillContext` (`episode/context.py`: the mind the cones
are made on, the camera, the trace); the DT's view-cone search (`episode/dt_search.py`) asks
it for the cones.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from functools import partial
from typing import Protocol

from avs_planner.episode.context import SkillContext
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.outcome import StepOutcome, StepStatus
from avs_planner.episode.state_builder import AvsState
from avs_planner.episode.viewcones import (
    CameraModel,
    ConeSet,
    p_at_support,
    room_cones,
    support_cones,
    support_relations,
)
from conceptual_map.conceptual.errors import ConceptualError

Location = tuple[str, str, str]  # (label, relation, location)
# a replacement of `support_cones` (same call): mind, support, p, camera, key -> cones
SupportViews = Callable[[Mind, KnownObject, float, CameraModel, str], ConeSet]


class WeightedCones(Protocol):
    """Cones weighted by what the robot knows beyond the map (QSR-weighted cones); None
    where it has nothing to add (the 2D cones are made instead)."""

    def support_cones(self, label: str, support: KnownObject, p_total: float, key: str
                      ) -> ConeSet | None: ...

    def room_cones(self, label: str, room: str, p_total: float, key: str
                   ) -> ConeSet | None: ...


class ConeSets:
    """The cone sets made in one episode (see the module's doc)."""

    def __init__(self, context: SkillContext) -> None:
        self.context = context
        self.cones: dict[Location, ConeSet] = {}
        # the map's P(ObjectAt) of each cone set's location when it was made: a later
        # search of it starts from what looks since then have left (`now`)
        self.basis: dict[Location, float] = {}
        self.support_views: SupportViews | None = None  # replaces support_cones
        self.qsr_cones: WeightedCones | None = None  # strategies/switching/qsr_cones.install

    def target_probability(self, label: str, relation: str, location: str, state: AvsState,
                           assumed: dict[str, str]) -> float | None:
        """P(ObjectAt) of the searched location under the plan's category assumption (the
        CP's own number); None to ask the conceptual map (no assumption about the room)."""
        assumed = {**{a[1]: a[2] for a in state.atoms if a[0] == "has-category"}, **assumed}
        if relation == "on":
            support = self.context.mind.objects.get(location)
            if support is None or support.room not in assumed:
                return None
            key = ("p-obj-on", label, support.label, assumed[support.room])
        else:
            if location not in assumed:
                return None
            key = ("p-obj-in", label, location, assumed[location])
        return state.values.get(key)

    def create(self, label: str, relation: str, location: str,
               p: float | None = None) -> StepOutcome:
        """CREATEVIEWCONES for `label` `relation` `location` with the location's probability
        `p` (None: the conceptual map's)."""
        ctx = self.context
        mind, camera = ctx.mind, ctx.camera
        key = f"{label}-{relation}-{location}"
        if relation == "on":
            support = mind.objects.get(location)
            if support is None:
                return StepOutcome(StepStatus.FAILED, f"{location} is not a known object")
            if p is None:  # on it and in it, where the knowledge puts the label
                p = p_at_support(mind, label, location, self._another(label))
            made = (self.support_views is None and self.qsr_cones
                    and self.qsr_cones.support_cones(label, support, p, key)) or \
                (self.support_views or partial(support_cones, relations=support_relations(
                    mind, label, support.label)))(mind, support, p, camera, key)
        else:
            if location not in mind.place_map.rooms:
                return StepOutcome(StepStatus.FAILED, f"{location} is not a known room")
            if p is None:
                p = mind.cmap.p_object_at(label, location, another=self._another(label))
            made = (self.qsr_cones and self.qsr_cones.room_cones(label, location, p, key)) or \
                room_cones(mind, location, label, p, camera, key)
        self.cones[(label, relation, location)] = made
        self.basis[(label, relation, location)] = self.location_belief(
            label, relation, location)
        mind.cones_made.add((label, relation, location))
        ctx.emit("action", action="createviewcones", cones=len(made.cones),
                 coverage=round(made.coverage, 3), probability=round(p, 4))
        if not made.cones:
            return StepOutcome(StepStatus.FAILED, "no view cone reachable")
        return StepOutcome(StepStatus.DONE, f"{len(made.cones)} cones")

    def _another(self, label: str) -> bool:
        """The task wants one more `label` beyond those reported (`Probabilities.another`)."""
        task = self.context.builder.task
        return label == task.target and bool(task.exclude)

    def location_belief(self, label: str, relation: str, location: str) -> float:
        """The map's P(ObjectAt) of the location itself (not its supports; a support's
        spaces the knowledge puts the label in: on it, in it)."""
        mind = self.context.mind
        try:
            if relation == "on":
                return p_at_support(mind, label, location, self._another(label))
            return mind.cmap.p_object_at(label, location, include_sublocations=False,
                                         another=self._another(label))
        except ConceptualError:  # a location the map no longer has: no rescaling
            return 0.0

    def now(self, label: str, relation: str, location: str) -> ConeSet | None:
        """The cone set of a location, its probabilities scaled by what looks since it was
        made (searches, glimpses) left of the map's P(ObjectAt) there: a desk searched once
        is not searched again from its prior."""
        made = self.cones.get((label, relation, location))
        then = self.basis.get((label, relation, location), 0.0)
        if made is None or then <= 0.0:
            return made
        scale = min(1.0, self.location_belief(label, relation, location) / then)
        if scale >= 1.0:
            return made
        cones = tuple(replace(c, probability=c.probability * scale) for c in made.cones)
        return replace(made, cones=cones, probability=made.probability * scale)
