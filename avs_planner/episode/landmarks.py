"""Furniture that tells what kind of room it is in: room landmarks.

The detector is asked for the target and its supports, so a bathroom's toilet or a kitchen's
fridge never reached the conceptual map, and a room's category rested on the place
classifier's readings and on whatever supports it held (a book found on a bathroom counter in
the robot's first look made that bathroom an office).

Every frame a skill takes (`SkillContext.detect`) also asks for the room landmarks, at no
extra sensing time: the knowledge's furniture labels, those no relation puts on or in
anything (a toilet, a sofa, a fridge), other than the target and the supports the watch asks
for anyway. A sighting starts a candidate at its spot; every later frame that had the spot in
view is evidence about it, whether it showed the label there or not:

- a frame showing the label within `agree` m of the spot is a hit: a real piece of furniture
  in view is seen with probability `hit` (the camera misses one in five), a phantom lands that
  near the spot with probability `fp_rate` x the share of the image the `agree` disc covers
  at that distance (phantoms fall where random rays through the image meet a surface);
- a frame that had the spot in view (inside the field of view and range, with a free line of
  sight on the occupancy grid that may end in the piece's own body) and did not show the
  label there is a miss.

The odds that a candidate is real start at `prior_odds` (a first sighting is much likelier a
phantom: 5% of frames carry one per label asked, over a dozen landmark labels, against the
few pieces in view) and are multiplied by each frame's likelihood ratio. At `confirm` the
candidate becomes a known object in the room whose floor holds it, evidence for the room's
category through the conceptual map's object model, like a support the robot confirms; a
candidate whose odds fall below `drop` is forgotten. Counting misses is what tells a real
piece from two phantoms that happen to fall near each other: a real one is seen in most
frames that have it in view, a phantom's spot in hardly any. Landmarks never enter the
planner's problem (the state builder keeps the target's and its supports' labels only).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from avs_planner.episode.context import FrameView, Listener, SkillContext
from avs_planner.episode.glimpses import Glimpses
from avs_planner.episode.outcome import SeenLike
from conceptual_map.knowledge import Knowledge


def landmark_labels(knowledge: Knowledge, asked: Sequence[str]) -> tuple[str, ...]:
    """The knowledge's furniture labels (no relation puts them on or in anything), without
    `asked` (the labels every frame asks for anyway)."""
    placed = {label for label, _, _ in knowledge.relation_lambda}
    return tuple(sorted(set(knowledge.labels) - placed - set(asked)))


@dataclass(frozen=True)
class LandmarkModel:
    """The evidence model of `episode/landmarks.py` (model parameters of the camera, not
    settings chosen on episodes)."""

    hit: float = 0.8  # a real piece in view is reported (the camera's miss rate is 0.2)
    fp_rate: float = 0.05  # phantoms per label asked per frame (the camera's)
    prior_odds: float = 0.1  # real : phantom for a first sighting
    confirm: float = 0.95  # P(real) at which a candidate becomes a known object
    drop: float = 0.001  # P(real) below which a candidate is forgotten
    body: float = 0.9  # m from the spot a ray may end in the piece's own body


@dataclass
class Candidate:
    """A landmark seen at a spot (the mean of its sightings), with the log-odds that it is
    real."""

    label: str
    position: tuple[float, float, float]
    log_odds: float = 0.0
    hits: int = 1
    misses: int = 0
    confirmed: bool = False  # waiting for the map to give its spot a room

    def add(self, xyz: tuple[float, float, float]) -> None:
        """One more sighting: the spot moves to the mean of all of them."""
        n = self.hits
        self.position = tuple((n * p + q) / (n + 1)  # type: ignore[assignment]
                              for p, q in zip(self.position, xyz, strict=True))
        self.hits += 1


class RoomLandmarks:
    """Landmarks in the frames the skills take, confirmed by hits against misses."""

    def __init__(self, context: SkillContext, labels: Sequence[str],
                 known_near: Callable[[Any], bool], views: Glimpses,
                 model: LandmarkModel | None = None) -> None:
        self.context, self.labels = context, tuple(labels)
        self.known_near = known_near  # reads `label` and `position` (a sighting, a candidate)
        self.views = views  # the frames' geometry: field of view, range, line of sight
        self.model = model or LandmarkModel()
        self.agree = context.config.agree[1]
        self.candidates: list[Candidate] = []
        self.confirmed = 0
        m = self.model
        self._miss = math.log((1.0 - m.hit) / (1.0 - m.fp_rate))
        self._confirm = math.log(m.confirm / (1.0 - m.confirm))
        self._drop = math.log(m.drop / (1.0 - m.drop))

    def listener(self) -> Listener:
        return Listener(self.labels, self.observe)

    def observe(self, seen: list[SeenLike], view: FrameView) -> None:
        """The detections of landmark labels in one frame taken from `view`."""
        hit: set[int] = set()
        for s in seen:
            if self.known_near(s):
                continue
            xyz = (float(s.position[0]), float(s.position[1]), float(s.position[2]))
            near = [c for c in self.candidates if c.label == s.label and id(c) not in hit
                    and math.dist(c.position[:2], xyz[:2]) <= self.agree]
            if not near:
                c = Candidate(s.label, xyz, math.log(self.model.prior_odds))
                self.candidates.append(c)
                hit.add(id(c))
                continue
            c = min(near, key=lambda c: math.dist(c.position[:2], xyz[:2]))
            c.add(xyz)
            c.log_odds += math.log(self.model.hit / self._phantom_near(c.position, view))
            hit.add(id(c))
        waiting = [c for c in self.candidates if id(c) not in hit and not c.confirmed]
        if waiting:
            shown = self._in_view([c.position for c in waiting], view)
            for c, missed in zip(waiting, shown.tolist(), strict=True):
                if missed:
                    c.misses += 1
                    c.log_odds += self._miss
        self.candidates = [c for c in self.candidates if c.log_odds >= self._drop]
        for c in list(self.candidates):
            if c.confirmed or c.log_odds >= self._confirm:
                c.confirmed = True
                self._place(c)

    def _phantom_near(self, spot: tuple[float, float, float], view: FrameView) -> float:
        """P(a phantom of a label falls within `agree` of `spot` in a frame from `view`):
        the phantom rate times the share of the image the disc covers at that distance."""
        cam = self.context.camera
        r = max(math.dist(spot[:2], view.pose[:2]), 1e-3)
        half = math.atan2(self.agree, r)
        share = min(1.0, 2.0 * half / cam.hfov)
        if cam.vfov is not None:
            share *= min(1.0, 2.0 * half / cam.vfov)
        return min(self.model.hit, max(1e-4, self.model.fp_rate * math.pi / 4.0 * share))

    def _in_view(self, spots: list[tuple[float, float, float]], view: FrameView
                 ) -> np.ndarray:
        """Per spot: inside the frame at its own height, with a free line of sight that
        may end in the piece's own body."""
        xyz = np.asarray(spots, dtype=float)
        ok = self.views.in_frame(xyz[:, :2], view.pose, view.pan, view.tilt, xyz[:, 2])
        idx = np.flatnonzero(ok)
        if len(idx):
            origin = np.asarray(view.pose[:2], dtype=float)
            ok[idx] = self.views.line_of_sight(origin, xyz[idx, :2], self.model.body)
        return ok

    def _place(self, c: Candidate) -> None:
        """A confirmed landmark becomes a known object once the map has a room for it."""
        mind = self.context.mind
        room = mind.room_at(c.position[:2], floor_only=True)
        if room is None:
            return
        self.candidates.remove(c)
        if self.known_near(c):
            return
        obj = mind.add_object(c.label, c.position, room=room)
        self.confirmed += 1
        self.context.emit("observation", label=c.label, detected=True, landmark=True,
                          position=[round(v, 2) for v in c.position], object=obj.id,
                          hits=c.hits, misses=c.misses)
