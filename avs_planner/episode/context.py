"""What every skill of the executor receives: the episode's robot, mind, state builder,
camera, settings (`ExecutorConfig`), tallies (`Stats`), trace and seed, as one `SkillContext`.

The executor (`episode/executor.py`) makes one context per episode and hands the same object to
each skill it composes: driving (`episode/driving.py`), sensing, the watch and confirmation
(`episode/sensing.py`), the look before a report (`episode/verifying.py`), the view cones
(`episode/cone_sets.py`) and the DT's view-cone search (`episode/dt_search.py`). The skills
read the context and never replace its members; the executor's `robot` and `config` setters
do, for every skill at once (a test's robot proxy, settings given after the executor was built).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from avs_planner.cp.search import DEFAULT_REWARD
from avs_planner.dt import DetectorModel
from avs_planner.episode.mind import Mind
from avs_planner.episode.outcome import SeenLike
from avs_planner.episode.robot_api import Robot
from avs_planner.episode.state_builder import StateBuilder
from avs_planner.episode.viewcones import CameraModel

Event = Callable[..., None]  # emit(type, **fields): a trace event


@dataclass
class ExecutorConfig:
    """How the executor drives, looks and confirms. Defaults whose comments cite episodes were
    chosen on development worlds and seeds (generated buildings below seed 10000, Fig. 3
    noise seeds 0-99), never on the held-out range (docs/experiments.md)."""

    leg: float = 1.0  # m driven between scans
    arrive: float = 0.35  # m from a MOVE's goal counts as there
    max_legs: int = 40
    replan_legs: int = 4  # legs driven on one A* path before searching again (the map grows)
    dt_policy: str = "pouct"
    # POUCT simulations per decision. The DT's own benchmark found 50 as good as 150 on its
    # synthetic instances, but in episodes 50 rejected searches that 150 confirmed (scenario
    # f, development seeds 0-19: 16/20 found with 50, 18/20 with 150; bench/episode_bench.py)
    dt_sims: int = 150
    # a look counts as a detection only when a second frame sees the label again within
    # `agree` m (a phantom rarely repeats), so misses are likelier and phantoms rarer than
    # the camera's own 0.2 / 0.05
    detector: DetectorModel = field(
        default_factory=lambda: DetectorModel(false_negative=0.36, false_positive=0.01))
    agree: tuple[float, float] = (0.25, 0.6)  # m, for the target / for supports (whose
    # detected centre moves with the part in view)
    squeeze: float = 0.08  # m less clearance when no path keeps the full margin
    # a leg the base refuses becomes a keep-out disc and the path is planned again around
    # it, up to this many times per move; then the move fails and the CP plans around it
    detours: int = 2
    # s of robot time: the CP's goal reward R, the DT's terminal penalties; the switching
    # strategy's executor is built with its `LoopConfig.reward` (one R per episode)
    miss_penalty: float = DEFAULT_REWARD
    # the detector looks for the target as the robot moves (`watch`; the loop's `watch`)
    watch: bool = True
    support_radius: float = 0.9  # m: a detection this near a support is "on" it
    same_object: float = 1.0  # m: a detection this near a known object of its label is it
    above_support: tuple[float, float] = (-0.15, 0.45)  # m around the support's top
    doorway_clearance: float = 0.6  # m from a mapped door: no place classification there
    # a target seen outside a DT search (while moving; the baselines) is reported only when
    # this many of the next frames see it again at the same spot
    confirm_needed: int = 2
    confirm_frames: int = 3
    # a confirmation that ends one short of `confirm_needed` with at least one frame agreeing
    # is ambiguous, not a rejection: it takes up to this many more frames. A real object (hit
    # in about 70% of frames at 3.6 m with the position noise against `agree`) then passes
    # 96% of the time instead of 78%; a phantom gets there only if another frame put a phantom
    # within `agree` of it, so phantoms cost no more frames than before
    confirm_extra: int = 2
    # a DT look whose second frame does not repeat the first detection takes a third frame
    # (`episode/dt_search.py`, `ViewConeSearch._look`); the DT's detector model above stays
    # the two-frame rule's, so it now slightly over-states misses
    dt_tiebreak: bool = True
    # before the target is reported the robot faces it and looks again: at least one of
    # this many frames must see it within `agree` m (0: report without looking). Two frames
    # that agree on a phantom are rare, but over the hundreds of looks of a search for an
    # absent object they happen (1 false report in 50 absent targets on generated worlds);
    # a phantom that also repeats at that spot is practically never seen, while a real
    # object in view is missed by all three frames with the camera's 0.2 only 0.8% of times
    verify_frames: int = 3
    # frames taken in passing (looking ahead while driving, both ways at a new place) that
    # do not show the target lower P(ObjectAt) where they looked, and supports they show
    # become known (`episode/glimpses.py`); the switching strategy turns this on
    # (`Executor.enable_glimpses`), the other strategies keep their own evidence rules
    glimpses: bool = False
    # directions the detector looks in at a new place (`look_around`): 2 is ahead and behind;
    # 6 covers the whole turn with the camera's 60 degree field of view
    look_headings: int = 2
    # a look around turns only to the headings whose frame is worth its time: one where
    # R x P(the frame shows a wanted label, as the glimpses leave it) is below the frame's
    # seconds is skipped, unless it would see space outside the entered rooms
    # (`Sensing.look_around`, `Glimpses.frame_value`); needs `glimpses`, the switching
    # strategy turns this on
    look_by_value: bool = False
    # every frame also asks for the knowledge's furniture labels, and one that the frames
    # with its spot in view mostly showed becomes a known object: evidence for its room's
    # category (`episode/landmarks.py`); the switching strategy turns this on
    landmarks: bool = False


@dataclass
class Stats:
    """What the skills tally for the summary and the pictures: metres driven, DT calls and
    decision times, views processed, the path (x, y, yaw, the room's likeliest category),
    and the detector's sightings (x, y, label, whether they counted)."""

    distance: float = 0.0
    dt_calls: int = 0
    dt_decisions: list[float] = field(default_factory=list)
    views: int = 0
    path: list[tuple[float, float, float, str]] = field(default_factory=list)
    detections: list[tuple[float, float, str, bool]] = field(default_factory=list)


@dataclass(frozen=True)
class FrameView:
    """Where a frame was taken from: the robot's pose (x, y, yaw) and the head's pan and tilt
    as the skills last set them (`SkillContext.look`)."""

    pose: tuple[float, float, float]
    pan: float = 0.0
    tilt: float = 0.0


@dataclass(frozen=True)
class Listener:
    """Labels some part of the mind wants to hear of in every frame, and what it does with
    their detections (with where the frame was taken from)."""

    labels: tuple[str, ...]
    observe: Callable[[list[SeenLike], FrameView], None]


@dataclass
class SkillContext:
    """One episode's parts every skill works with (see the module's doc). `listeners`: see
    `detect`."""

    robot: Robot
    mind: Mind
    builder: StateBuilder
    camera: CameraModel
    config: ExecutorConfig
    stats: Stats
    emit: Event
    seed: int = 0
    listeners: list[Listener] = field(default_factory=list)
    head: tuple[float, float] = (0.0, 0.0)  # (pan, tilt) last set through `look`

    def look(self, pan: float, tilt: float) -> None:
        """Point the head; the skills point it here, so a frame's listeners know where it
        looked."""
        self.robot.look(pan, tilt)
        self.head = (float(pan), float(tilt))

    def detect(self, labels: Sequence[str]) -> list[SeenLike]:
        """One frame of the detector, for `labels`: every skill takes its frames here. The
        same frame is asked for the listeners' labels too (a detector reports all it
        recognises in one frame, at no extra sensing time); each listener hears of the
        detections of its labels, the skill gets those of its own."""
        asked = list(labels)
        if not self.listeners:
            return list(self.robot.detect(asked))
        extra = list(dict.fromkeys(lb for listener in self.listeners for lb in listener.labels
                                   if lb not in asked))
        frame = list(self.robot.detect(asked + extra))
        x, y, yaw = self.robot.pose
        view = FrameView((float(x), float(y), float(yaw)), *self.head)
        for listener in self.listeners:
            listener.observe([s for s in frame if s.label in listener.labels], view)
        return [s for s in frame if s.label in asked]
