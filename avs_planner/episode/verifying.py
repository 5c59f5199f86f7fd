"""Where a report's verification means something: a phantom's chance to agree by accident.

A phantom (the detector's false positive, `fp_rate` of frames) lands where a random ray
through the image meets a surface. Frames agree on a spot when they see the label within
`agree` (0.25 m) of it, and the chance that a phantom does so by accident is the share of the
view's cross-section at that distance within `agree` of the spot. Two metres away that is
about 5% of a 60 x 45 degree view; facing a wall 0.4 m away the whole view is within 0.25 m
of every point on it, so every phantom agrees and "two of three frames" only asks for
phantoms in two more frames (generated office 23, `most-likely-room`: a phantom stapler at
0.39 m; development apartment 325, the switching planner: a phantom book at 0.49 m). So
before a report the robot steps back to where agreement means something (at most
`MAX_ACCIDENTAL`) when it can reach such a spot.

`Verifier` is that skill of the executor (`Executor.verify_report`, which the strategies call
too): it receives the executor's `SkillContext` (`episode/context.py`), the driving skill
(`Driver`, for the step back) and the sensing skill (`Sensing.confirm`, for the frames).
"""

from __future__ import annotations

import math

import numpy as np

from avs_planner.episode.context import SkillContext
from avs_planner.episode.driving import Driver
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import SeenLike
from avs_planner.episode.sensing import Sensing
from conceptual_map.metric import PathQueryError, distance_field

MAX_ACCIDENTAL = 0.1  # a report's verification must come from where a phantom agrees by
# chance at most this often
STEP_BACK_TURNS = (0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5)  # rad off the line from the object
# to the robot, tried in this order for the standpoint of a verification from further away


def accidental_agreement(distance: float, agree: float, hfov: float, vfov: float) -> float:
    """The chance that a phantom in a view lands within `agree` m of a point `distance` m
    from the camera (the disc's share of the view's cross-section there, at most 1)."""
    section = 4.0 * distance**2 * math.tan(hfov / 2.0) * math.tan(vfov / 2.0)
    return 1.0 if section <= 0.0 else min(1.0, math.pi * agree**2 / section)


def verify_distance(agree: float, hfov: float, vfov: float,
                    accidental: float = MAX_ACCIDENTAL) -> float:
    """The camera distance beyond which `accidental_agreement` is at most `accidental`."""
    return agree * math.sqrt(math.pi / (4.0 * accidental * math.tan(hfov / 2.0)
                                        * math.tan(vfov / 2.0)))


def step_back(grid, robot_radius: float, pose: tuple[float, float, float],  # noqa: ANN001
              camera_height: float, position, distance: float  # noqa: ANN001 - xyz
              ) -> tuple[float, float] | None:
    """A reachable free spot whose camera is `distance` m from `position`, on the robot's
    side of it (the line from it to the robot, turned by `STEP_BACK_TURNS` in turn)."""
    x, y, _ = pose
    dz = camera_height - position[2]
    flat = math.sqrt(max(distance**2 - dz**2, 0.0))
    if flat <= 0.0:
        return None
    try:
        reach = distance_field(grid, (x, y), robot_radius)
    except PathQueryError:  # the robot off the map: no step back
        return None
    away = math.atan2(y - position[1], x - position[0])
    for turn in STEP_BACK_TURNS:
        goal = (position[0] + flat * math.cos(away + turn),
                position[1] + flat * math.sin(away + turn))
        cell = grid.cell_of(goal)
        if grid.contains(cell) and np.isfinite(reach[tuple(cell)]):
            return goal
    return None


class Verifier:
    """The look before a report: face the object from where agreement means something and
    see it again (see the module's doc)."""

    def __init__(self, context: SkillContext, driver: Driver, sensing: Sensing) -> None:
        self.context = context
        self.driver = driver
        self.sensing = sensing

    def verify_report(self, obj: KnownObject | SeenLike) -> bool:
        """`verify` from a camera distance where frames agree by accident at most
        `MAX_ACCIDENTAL` of the time: stepping back there first when the robot stands
        closer and can reach such a spot. Without a body: `verify`."""
        ctx = self.context
        body = ctx.mind.body
        if body is None:
            return self.verify(obj)
        x, y, _ = ctx.robot.pose
        distance = math.dist((x, y, body.camera_height), obj.position)
        needed = min(verify_distance(ctx.config.agree[0], body.hfov, body.vfov),
                     0.9 * body.detect_range)
        if distance < needed:
            here = ctx.robot.pose
            stand = step_back(ctx.mind.grid, ctx.mind.config.robot_radius, here,
                              body.camera_height, obj.position, needed)
            ctx.emit("action", action="(step-back)", status="start" if stand else "failed",
                     distance=round(distance, 2), needed=round(needed, 2))
            if stand is not None:
                self.driver.drive_to(stand)
                if self.verify(obj):
                    return True
                return self._verify_again_from(here, obj)
        return self.verify(obj)

    def _verify_again_from(self, here: tuple[float, float, float],
                           obj: KnownObject | SeenLike) -> bool:
        """After a step back whose frames all missed `obj`: back where the robot stood, two
        of `verify_frames` frames must see it. The spot stepped back to may look at the
        object past the side of the shelf or cupboard it stands in (development lab 301: a
        book confirmed from 1.0 m in front of a shelf, looked for from 0.5 rad to the side,
        missed in all three frames and forgotten, was found again 22 s later). Closer, a
        phantom agrees by accident more often (at most always, facing a wall), so one frame
        in three is not enough there; two in three is: a phantom passes that with
        3 (fp a)^2 <= 0.75% at fp = 5% of frames and any accidental share a, below what one
        frame in three from the step-back spot allows, 1 - (1 - fp x 0.1)^3 = 1.5%, while an
        object in view, missed in 20% of frames, still passes 90% of the time."""
        ctx = self.context
        if ctx.config.verify_frames < 2:
            return False
        ctx.emit("action", action="(step-back)", status="undone",
                 detail="not seen from further back: looking again from where it was seen")
        self.driver.drive_to(here[:2])
        return self.verify(obj, needed=2)

    def verify(self, obj: KnownObject | SeenLike, needed: int = 1) -> bool:
        """Face `obj` and look at it: True when `needed` of `verify_frames` frames see its
        label within `agree` m of where it was found (always True with 0 frames)."""
        ctx = self.context
        frames = ctx.config.verify_frames
        if frames <= 0:
            return True
        x, y, _ = ctx.robot.pose
        dx, dy = obj.position[0] - x, obj.position[1] - y
        ctx.robot.turn_to(math.atan2(dy, dx))
        ctx.look(0.0, -math.atan2(ctx.camera.height - obj.position[2],
                                  max(math.hypot(dx, dy), 0.1)))
        seen = self.sensing.confirm(obj, needed=min(needed, frames), frames=frames)
        ctx.emit("observation", label=obj.label, detected=seen, verifying=True,
                 position=[round(v, 2) for v in obj.position])
        return seen
