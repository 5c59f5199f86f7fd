"""QSR-weighted view cones of the switching planner
(avs_planner/strategies/switching/qsr_cones.py): on a constructed desk the cones follow the
described side of the keyboard; landmarks come only from the robot's detections (the detector
tap); the strategy option is checked."""

import math
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest

from avs_planner.episode.context import FrameView, SkillContext, Stats
from avs_planner.episode.executor import ExecutorConfig
from avs_planner.episode.mind import KnownObject, Mind
from avs_planner.episode.viewcones import CameraModel, support_cones
from avs_planner.strategies.switching.qsr_cones import QsrCones, install, knowledge_for
from conceptual_map.metric import OccupancyGrid
from conceptual_map.qsr import load_qsr, parse_descriptions

# a 3 m counter against the north wall of a 6 x 7 m room, a keyboard and monitor in its middle;
# a 2 m recognition range, so that no one view covers the whole counter
CAMERA = CameraModel(height=1.4, hfov=math.radians(60), detect_range=2.0)
COUNTER = KnownObject("counter1", "counter", (3.0, 5.5, 0.45), "lab")
KEYBOARD = (3.0, 5.35, 0.915)
MONITOR = (3.0, 5.7, 1.1)
CONFIG = ExecutorConfig(support_radius=1.6)  # the counter's half length and a little more


def _grid() -> OccupancyGrid:
    grid = OccupancyGrid((0.0, 0.0), (6.0, 7.0), 0.05)
    m = grid.model
    grid.logodds[...] = m.clamp_min
    grid.logodds[[0, -1], :] = m.clamp_max
    grid.logodds[:, [0, -1]] = m.clamp_max
    grid.logodds[30:90, 104:140] = m.clamp_max  # x 1.5..4.5, y 5.2..7.0: counter to the wall
    grid._touch()
    return grid


@dataclass
class Seen:
    label: str
    position: tuple[float, float, float]


class FakeRobot:
    """Reports what a camera would see on desk1 for the labels asked, and the asks."""

    pose = (3.0, 4.0, math.pi / 2)

    def __init__(self) -> None:
        self.asked: list[list[str]] = []

    def detect(self, labels):  # noqa: ANN001, ANN201
        self.asked.append(list(labels))
        scene = [Seen("keyboard", KEYBOARD), Seen("monitor", MONITOR),
                 Seen("cup", (3.7, 5.35, 0.95))]
        return [s for s in scene if s.label in labels]


def _executor(robot: FakeRobot | None = None) -> SimpleNamespace:
    mind = Mind()
    mind.grid = _grid()
    mind.objects["counter1"] = COUNTER
    events: list[tuple[str, dict]] = []
    robot = robot or FakeRobot()

    def emit(kind: str, **fields: object) -> None:
        events.append((kind, fields))

    context = SkillContext(robot, mind, None, CAMERA, CONFIG, Stats(), emit)  # type: ignore[arg-type]
    return SimpleNamespace(mind=mind, config=CONFIG, camera=CAMERA, seed=0, robot=robot,
                           qsr_cones=None, events=events, emit=emit, context=context)


def _knowledge(side: str):  # noqa: ANN202
    return parse_descriptions([{"target": "cup", "relations": [side, "distant"],
                                "of": "keyboard", "count": 1}], load_qsr())


def _seen_twice(qsr: QsrCones) -> None:
    for _ in range(2):
        qsr.observe([Seen("keyboard", KEYBOARD), Seen("monitor", MONITOR)],
                    FrameView((3.0, 4.0, 0.0)))


def _covers(cone, point: tuple[float, float]) -> bool:  # noqa: ANN001
    x, y, yaw = cone.pose
    bearing = math.atan2(point[1] - y, point[0] - x) - yaw
    bearing = abs((bearing + math.pi) % (2 * math.pi) - math.pi)
    return bearing <= CAMERA.hfov / 2 and math.dist((x, y), point) <= 0.9 * CAMERA.detect_range


@pytest.mark.parametrize(("side", "there", "not_there"), [
    ("right", (3.7, 5.35), (2.3, 5.35)),  # seen from the front (-y), right is +x
    ("left", (2.3, 5.35), (3.7, 5.35)),
])
def test_cone_weights_favour_the_described_side_of_the_keyboard(side, there, not_there):
    ex = _executor()
    qsr = QsrCones(ex, _knowledge(side), "cup", "task")
    _seen_twice(qsr)
    made = qsr.support_cones("cup", COUNTER, 0.6, "k")
    uniform = support_cones(ex.mind, COUNTER, 0.6, CAMERA, "k")
    assert made is not None and made.cones and uniform.cones
    best = max(made.cones, key=lambda c: c.probability)
    assert _covers(best, there) and not _covers(best, not_there)
    # most of P(ObjectAt) goes to the views of the described side, far more than the uniform
    # cones' own lean (from where they can stand)
    assert best.probability > 0.6 / len(uniform.cones) * 1.5
    assert sum(c.probability for c in made.cones) == pytest.approx(0.6)
    on_side = sum(c.probability for c in made.cones if _covers(c, there))
    off_side = sum(c.probability for c in made.cones if _covers(c, not_there))
    assert on_side > 0.7 * 0.6 and off_side < 0.3 * 0.6
    even_on = sum(c.probability for c in uniform.cones if _covers(c, there))
    even_off = sum(c.probability for c in uniform.cones if _covers(c, not_there))
    assert on_side - off_side > (even_on - even_off) + 0.2 * 0.6
    # the planner's density puts the bulk of its mass on the described side of the keyboard
    found = qsr.density(COUNTER)
    side_x = np.sign(there[0] - KEYBOARD[0])
    assert found.weights[np.sign(found.points[:, 0] - KEYBOARD[0]) == side_x].sum() > 0.8


def test_no_landmark_seen_or_another_label_keeps_the_uniform_cones():
    ex = _executor()
    qsr = QsrCones(ex, _knowledge("right"), "cup", "task")
    # one sighting is no landmark
    qsr.observe([Seen("keyboard", KEYBOARD)], FrameView((3.0, 4.0, 0.0)))
    assert qsr.support_cones("cup", COUNTER, 0.6, "k") is None
    _seen_twice(qsr)
    assert qsr.support_cones("stapler", COUNTER, 0.6, "k") is None  # not the QSR target
    qsr.weighting = False  # the option's "observe"
    assert qsr.support_cones("cup", COUNTER, 0.6, "k") is None


def test_install_listens_to_every_frame_for_landmark_labels_and_hides_them_from_callers():
    """Every frame a skill takes (`SkillContext.detect`) also asks for the landmark labels; the
    robot itself is not touched (its members cannot be replaced: replacing its `detect` made
    every episode with QSR cones end in an internal error)."""
    robot = FakeRobot()
    ex = _executor(robot)
    qsr = install(ex, _knowledge("right"), "cup")
    assert ex.qsr_cones is qsr and qsr.labels == ("keyboard",)
    for _ in range(2):
        seen = ex.context.detect(["cup"])
        assert [s.label for s in seen] == ["cup"]  # the caller gets what it asked for
    assert robot.asked[-1] == ["cup", "keyboard"]  # one frame for both: no extra time
    assert [lm.label for lm in qsr.landmarks()] == ["keyboard"]
    # the keyboard faces the open side of the map: towards the room (-y)
    assert abs(qsr.landmarks()[0].facing + math.pi / 2) < math.radians(20)


def test_knowledge_for_prefers_the_task_and_falls_back_to_the_default():
    task = _knowledge("left")
    assert knowledge_for(task, "cup") == (task, "task")
    assert knowledge_for(None, "cup")[1] == "default"
    assert knowledge_for(task, "laptop")[1] == "default"  # the task says nothing of laptops
    assert knowledge_for(None, "sofa") is None


def test_the_switching_option_is_checked():
    from avs_planner.harness import run_episode
    from avs_planner.strategies.registry import StrategyError

    with pytest.raises(StrategyError, match="qsr_cones"):
        run_episode({"target": "cup", "world": "qsr_desks_a", "strategy": "switching",
                     "strategy_options": {"qsr_cones": "maybe"}, "time_budget_s": 5})


def test_room_cones_keep_the_uniform_set_and_coverage_and_lean_half_on_the_density(
        monkeypatch):
    """In a room the cones and their coverage stay the uniform ones (a rejected room is no
    more certain than before); half of their probability follows the QSR density."""
    import avs_planner.strategies.switching.qsr_cones as module
    from avs_planner.dt import ViewCone
    from avs_planner.episode.viewcones import ConeSet

    east = ViewCone("r-0", (3.0, 4.3, 0.0), 0.3)  # looks along y = 4.3, away from the counter
    north = ViewCone("r-1", (3.0, 4.3, math.pi / 2), 0.2)  # looks at the counter
    uniform = ConeSet((east, north), 0.5, 0.8)
    cells = np.array([[4.0, 4.3], [4.5, 4.3], [2.3, 5.35], [3.7, 5.35], [3.3, 5.35]])
    monkeypatch.setattr(module, "room_cones", lambda *args: uniform)
    monkeypatch.setattr(module, "_room_cells", lambda *args: cells)
    ex = _executor()
    ex.mind.room_at = lambda xy: "lab"
    qsr = QsrCones(ex, _knowledge("right"), "cup", "task")
    _seen_twice(qsr)
    made = qsr.room_cones("cup", "lab", 0.8, "r")
    assert [c.pose for c in made.cones] == [east.pose, north.pose]
    assert (made.coverage, made.probability) == (0.5, 0.8)
    assert sum(c.probability for c in made.cones) == pytest.approx(0.5)
    by_id = {c.id: c.probability for c in made.cones}
    assert by_id["r-1"] > 0.2 and by_id["r-0"] < 0.3  # towards the keyboard's right
    assert by_id["r-1"] <= 0.5 * 0.5 + 0.5 * 0.2 + 1e-9  # only half follows the density
    assert qsr.room_cones("stapler", "lab", 0.8, "r") is None


@pytest.mark.parametrize("mode", ["on", "observe"])
def test_an_episode_with_qsr_cones_runs_to_its_end(mode: str) -> None:
    """The option end to end on the QSR desks world: the keyboard is found (both modes
    ended in an internal error while `install` replaced the fenced robot's `detect`)."""
    from avs_planner.harness import Episode, EpisodeSpec

    summary = Episode(EpisodeSpec.from_dict(
        {"target": "keyboard", "world": "qsr_desks", "seed": 0,
         "strategy_options": {"qsr_cones": mode}})).run()
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]
