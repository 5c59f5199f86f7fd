"""The robot's body in the loop: doors vs footprint, blocked moves as evidence, no repeats."""

from __future__ import annotations

import math

import pytest

from avs_planner.episode.executor import Executor
from avs_planner.episode.mind import Mind
from avs_planner.episode.outcome import StepOutcome, StepStatus
from avs_planner.episode.state_builder import SearchTask, StateBuilder
from avs_planner.episode.trace import Trace
from avs_planner.episode.viewcones import CameraModel
from avs_planner.harness import Episode, EpisodeSpec
from avs_planner.harness.sim_robot import load_spec, open_world
from avs_planner.strategies.switching.loop import SwitchingLoop, _signature

_WORLD = """name: door_{w}
size: [15.0, 5.0]
wall_height: 2.0
rooms:
  - {{name: hall, category: office, rect: [0.0, 0.0, 5.0, 5.0]}}
  - {{name: kitchen, category: kitchen, rect: [5.0, 0.0, 15.0, 5.0]}}
doors:
  - {{rooms: [hall, kitchen], at: [5.0, 2.5], width: {w}}}
furniture:
  - {{name: table1, label: table, room: kitchen, pose: [12.5, 2.5, 0.0], size: [1.2, 0.8, 0.75]}}
objects:
  - {{name: cereal1, label: cerealbox, on: table1, offset: [0.0, 0.0], size: [0.2, 0.07, 0.3]}}
robot: {{model: pioneer, start: [2.5, 2.5, 0.0]}}
"""


def _episode(width: float, robot: str) -> tuple[dict, Episode]:
    spec = EpisodeSpec.from_dict({"target": "cerealbox", "world_file": _WORLD.format(w=width),
                                  "robot": robot, "seed": 1, "time_budget_s": 900.0})
    episode = Episode(spec)
    return episode.run(), episode


def test_the_mind_plans_with_the_robots_own_footprint() -> None:
    for model, radius in (("pioneer", 0.30), ("pr2", 0.36)):
        robot = open_world(load_spec("office", model), 0)
        try:
            assert Mind.for_body(robot.body()).config.robot_radius == pytest.approx(radius)
        finally:
            robot.world.close()


def test_a_door_narrower_than_the_pr2_is_never_planned_through_and_named() -> None:
    summary, episode = _episode(0.6, "pr2")
    assert summary["outcome"] == "gave_up"
    # the grid's width of the door (0.6 m) and what the PR2 squeezes through at the least
    # (0.29 m disc + the grid's half-cell under-estimate each side: 0.65 m)
    assert "needs 0.65 m" in summary["reason"] and "wide at (4.9" in summary["reason"]
    width = float(summary["reason"].split("about ")[1].split(" m wide")[0])
    assert 0.5 <= width <= 0.65
    assert all(x < 5.0 for x, *_ in episode.executor.stats.path)  # never went through
    assert not episode.mind.blockages.items  # never even tried (so never blocked)


@pytest.mark.parametrize("robot", ["pioneer", "pr2"])
def test_a_door_wider_than_the_robot_is_passed(robot: str) -> None:
    summary, episode = _episode(0.9, robot)
    assert summary["outcome"] == "found" and summary["correct"]
    # the table stands 7.5 m beyond the door, out of the detector's range from it
    assert any(x > 5.5 for x, *_ in episode.executor.stats.path)


class _HiddenObstacle:
    """A robot adapter whose base also refuses legs through a disc no scan shows (a low box
    under the laser), reporting the contact point like the simulator does."""

    def __init__(self, robot, centre: tuple[float, float], radius: float):  # noqa: ANN001
        self._robot, self.centre, self.radius = robot, centre, radius
        self.refused = 0

    def __getattr__(self, name: str):  # noqa: ANN204 - delegate everything else
        return getattr(self._robot, name)

    def move_along(self, path: list[tuple[float, float]]) -> bool:
        reach = self.radius + self._robot.robot.model.footprint_radius
        x, y = self._robot.pose[:2]
        for px, py in path:
            n = max(2, int(math.dist((x, y), (px, py)) / 0.02) + 1)
            for k in range(n):
                cx, cy = x + (px - x) * k / (n - 1), y + (py - y) * k / (n - 1)
                d = math.dist((cx, cy), self.centre)
                if d < reach:  # the rim point toward the obstacle touched it
                    self.refused += 1
                    rim = self._robot.robot.model.footprint_radius / d
                    self._robot.last_contact = (cx + (self.centre[0] - cx) * rim,
                                                cy + (self.centre[1] - cy) * rim)
                    return False
            x, y = px, py
        return self._robot.move_along(path)


def _executor(sim, robot) -> tuple[Mind, Executor, list[tuple]]:  # noqa: ANN001
    """An executor for `robot` (the adapter `sim`, or a wrapper of it) that has looked around
    once; its events are collected."""
    mind = Mind.for_body(sim.body())
    builder = StateBuilder(mind, SearchTask("cerealbox"))
    events: list[tuple] = []
    executor = Executor(robot, mind, builder, CameraModel(sim.camera_height, 1.0, 3.5),
                        lambda *a, **k: events.append((a, k)))
    executor.look_around()
    return mind, executor, events


def test_a_move_blocked_by_an_unmapped_obstacle_goes_around_it() -> None:
    sim = open_world(load_spec("office", start=(6.0, 3.2, 0.0)), seed=1)
    try:
        robot = _HiddenObstacle(sim, (8.0, 2.9), 0.1)
        mind, executor, events = _executor(sim, robot)
        outcome = executor.drive_to((10.0, 3.2))
        assert outcome.status is StepStatus.DONE, outcome.detail
        assert 1 <= robot.refused <= 2 and len(mind.blockages.items) == robot.refused
        assert any(k.get("blocked") for _, k in events)  # the trace reports it
        assert math.dist(sim.pose[:2], (10.0, 3.2)) <= executor.config.arrive
    finally:
        sim.world.close()


def _run_recording(loop: SwitchingLoop) -> tuple:
    """Run the loop, recording each executed (step, belief state signature)."""
    executed: list[tuple[str, int]] = []
    run = loop._execute

    def record(step, state):  # noqa: ANN001, ANN202
        executed.append((step.label, _signature(state)))
        return run(step, state)

    loop._execute = record
    return loop.run(), executed


def test_no_failed_action_is_repeated_from_an_unchanged_state(
        corridor, switching_loop) -> None:  # noqa: ANN001
    """Every move is refused (with no contact point to learn from): the episode must end
    with a reason, never re-running a failed action from the same belief state."""
    mind, builder, executor = corridor
    executor.robot.move_along = lambda path: False
    loop = switching_loop(builder, executor, Trace(lambda: executor.robot.clock, None, None))
    result, executed = _run_recording(loop)
    assert result.outcome.value == "gave_up", result.reason
    assert executed and len(executed) == len(set(executed))
    assert mind.failed_moves


def test_a_move_that_takes_no_time_and_changes_nothing_is_not_planned_again(
        corridor, switching_loop) -> None:  # noqa: ANN001
    """The base "arrives" without moving (the drive ends at once): the step took no time and
    the belief state is unchanged, so the same move from the same state would do nothing
    again. It is withheld, like a failed move, instead of replanned at the same instant."""
    mind, builder, executor = corridor
    executor.drive_to = lambda goal, stop=None: StepOutcome(StepStatus.DONE)
    executor.look_around = lambda: None  # arrived at a placeholder: nothing new either
    # this rule alone: a placeholder reached and still there also counts as tried out
    # (`Executor._frontier_stays`, tested below), which would change the state first
    executor._frontier_stays = lambda target: None
    events: list[dict] = []
    trace = Trace(lambda: executor.robot.clock, None, None)
    trace.subscribe(events.append)
    result, executed = _run_recording(switching_loop(builder, executor, trace))
    assert result.outcome.value == "gave_up", result.reason
    assert executed and len(executed) == len(set(executed))
    no_effect = [e["no_effect"] for e in events if e.get("no_effect")]
    assert no_effect and all(label.startswith("(move") for label in no_effect)
    assert mind.failed_moves


def test_a_blockage_at_a_door_names_it_cuts_edges_and_expires() -> None:
    from avs_planner.episode.blockages import Blockages
    from conceptual_map.places.model import Door

    door = Door("door3", (5.0, 2.5), 0.8, ((5.0, 2.1), (5.0, 2.9)), True)
    ledger = Blockages(retry_after=100.0)
    b = ledger.add((5.0, 2.1), time=10.0, doors={"door3": door}, planning_radius=0.34)
    assert b.door == "door3" and "door door3 (0.80 m wide)" in b.describe()
    assert b.radius == pytest.approx(0.39)
    assert ledger.cutting((3.0, 2.3), (7.0, 2.3)) is b
    assert ledger.cutting((3.0, 0.5), (7.0, 0.5)) is None
    again = ledger.add((5.0, 2.15), time=11.0, doors={"door3": door}, planning_radius=0.34)
    assert again.radius == pytest.approx(0.44)  # a second touch there: a wider berth
    before = ledger.signature()
    assert ledger.expire(50.0) == [] and ledger.signature() == before
    assert ledger.expire(110.0) == [b] and ledger.expire(111.0) == [again] and not ledger.items


def test_a_failed_move_is_withheld_until_something_new_is_learned(corridor) -> None:  # noqa: ANN001
    mind, builder, _ = corridor
    state = builder.build()
    hub = state.robot_place
    target = next(b for a in state.atoms if a[0] == "connected" and a[1] == hub
                  for b in [a[2]])
    mind.move_failed(target)
    assert ("connected", hub, target) not in builder.build().atoms
    far = tuple(v + 50.0 for v in mind.place_map.places[hub].position)
    mind.block(far, time=1.0)  # new evidence (elsewhere): the move may be tried again
    assert ("connected", hub, target) in builder.build().atoms
    a, b = mind.place_map.places[hub].position, builder.build().positions[target]
    mind.block(((a[0] + b[0]) / 2, (a[1] + b[1]) / 2), time=2.0)  # on the way
    lengths = builder._edge_length(hub, target, mind.place_map.graph.edges[hub, target])
    assert lengths is None


def test_blocked_spots_are_retried_when_nothing_else_is_left_at_most_twice(
        corridor, switching_loop) -> None:  # noqa: ANN001
    mind, builder, executor = corridor
    loop = switching_loop(builder, executor, Trace(lambda: executor.robot.clock, None, None))
    here = executor.robot.pose[:2]
    for k in range(3):
        mind.block((here[0] + 2.0, here[1]), time=float(k))
        assert mind.grid.keep_out
        assert loop._retry_blocked() is (k < 2)
    assert len(mind.blockages.seen) == 3
    assert [round(b.radius, 2) for b in mind.blockages.seen.values()] == [0.35, 0.4, 0.45]
    assert "touched something unmapped" in loop._cut_off()


def test_an_opening_is_measured_on_the_widest_route_not_the_shortest_slim_one() -> None:
    """Room B is seen through a 0.4 m gap (on the short way) and a 0.8 m door (further): for a
    robot that passes neither, the door is reported 0.8 m wide where it is. The narrowest
    point of the shortest path a slim robot could take was reported before (0.42 m, off the
    door), so a door a robot does pass looked too narrow from where it was seen."""
    from avs_planner.episode.blockages import narrow_openings
    from conceptual_map.metric import OccupancyGrid
    from conceptual_map.metric.synthetic import rooms_world

    world = rooms_world([(0, 0, 4, 4), (4, 0, 8, 4)], [(4.0, 0.8, 0.4), (4.0, 3.0, 0.8)],
                        wall=0.1)
    grid = OccupancyGrid()
    for pose in [(2.0, 0.8, 0.0), (2.0, 3.0, 0.0), (3.2, 2.0, 0.0), (3.0, 0.8, 0.0)]:
        grid.integrate_scan(world.laser(pose, beams=2880, max_range=8.0))
    found = narrow_openings(grid, (2.0, 0.8), 0.45, {})
    door = min(found, key=lambda o: math.dist(o.centre, (4.0, 3.0)))
    assert math.dist(door.centre, (4.0, 3.0)) < 0.2 and door.width == pytest.approx(0.8, abs=0.05)
    gap = min(found, key=lambda o: math.dist(o.centre, (4.0, 0.8)))
    assert math.dist(gap.centre, (4.0, 0.8)) < 0.2 and gap.width == pytest.approx(0.4, abs=0.05)
    # a robot that squeezes through 0.8 m reaches room B through the door: only the space
    # seen through the 0.4 m gap alone is left unreachable
    left = narrow_openings(grid, (2.0, 0.8), 0.36, {})
    assert [math.dist(o.centre, (4.0, 0.8)) < 0.2 for o in left] == [True]


_GAP_WORLD = """name: gap_{gap}
size: [10.0, 5.0]
wall_height: 2.0
rooms:
  - {{name: hall, category: office, rect: [0.0, 0.0, 5.0, 5.0]}}
  - {{name: kitchen, category: kitchen, rect: [5.0, 0.0, 10.0, 5.0]}}
doors:
  - {{rooms: [hall, kitchen], at: [5.0, 1.0], width: 1.0}}
furniture:
  - {{name: fridge1, label: fridge, room: kitchen, pose: [6.8, {centre}, 0.0],
     size: [0.4, {length}, 1.9]}}
  - {{name: table1, label: table, room: kitchen, pose: [8.5, 1.5, 0.0], size: [1.0, 0.8, 0.75]}}
objects:
  - {{name: cereal1, label: cerealbox, on: table1, offset: [0.0, 0.0], size: [0.2, 0.07, 0.3]}}
robot: {{model: pioneer, start: [2.5, 2.5, 0.0]}}
"""


@pytest.mark.parametrize("robot", ["pioneer", "pr2"])
def test_a_target_behind_a_gap_the_grid_under_measures_is_found(robot: str) -> None:
    """A tall fridge row leaves a 0.74 m gap to the wall, the only way to the table: the PR2
    (0.68 m) passes it, but the grid (a lower bound on clearance) shows it narrower than the
    0.72 m planning disc. The space behind it is a placeholder the robot squeezes to."""
    gap, low = 0.74, 0.06
    top = 4.95 - gap  # the wall's inner face is at 4.95
    world = _GAP_WORLD.format(gap=gap, centre=round((top + low) / 2, 3),
                              length=round(top - low, 3))
    spec = EpisodeSpec.from_dict({"target": "cerealbox", "world_file": world, "robot": robot,
                                  "seed": 1, "time_budget_s": 900.0})
    summary = Episode(spec).run()
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]


def test_retrying_blocked_spots_brings_back_the_placeholders_they_cut_off() -> None:
    """A blockage in the only door hides the room beyond; when the loop retries blocked spots
    (nothing else left) the placeholder there is a goal again at once, not after the next
    scan (the planner saw no goal and gave up: generated office world 4, pr2, keyboard)."""
    from conceptual_map.metric.synthetic import rooms_world

    world = rooms_world([(0.0, 0.0, 4.0, 4.0), (4.0, 0.0, 9.0, 4.0)], [(4.0, 2.0, 1.0)],
                        wall=0.1)
    mind = Mind()

    def sense(pose: tuple[float, float, float], time: float) -> None:
        mind.sense(world.laser(pose, beams=1440, fov=4.18, max_range=5.6), [pose], time)

    sense((2.0, 2.0, 0.0), 0.0)
    sense((2.0, 2.0, math.pi), 1.0)
    beyond = [p for p in mind.place_map.placeholders.values() if p.position[0] > 4.2]
    assert beyond
    mind.block((4.0, 2.0), 5.0)
    sense((2.0, 2.0, 0.0), 6.0)
    assert not [p for p in mind.place_map.placeholders.values() if p.position[0] > 4.2]
    assert mind.retry_blocked()
    back = [p for p in mind.place_map.placeholders.values() if p.position[0] > 4.2]
    assert back and all(p.id in mind.cmap.placeholders for p in back)


_OBLIQUE_WORLD = """name: oblique
size: [12.0, 6.0]
wall_height: 2.0
rooms:
  - {name: corridor, category: corridor, rect: [0.0, 0.0, 12.0, 1.8]}
  - {name: office, category: office, rect: [0.0, 1.8, 8.0, 6.0]}
  - {name: kitchen, category: kitchen, rect: [8.0, 1.8, 12.0, 6.0]}
doors:
  - {rooms: [corridor, office], at: [1.2, 1.8], width: 0.9}
  - {rooms: [corridor, kitchen], at: [10.8, 1.8], width: 0.75}
furniture:
  - {name: desk1, label: desk, room: office, pose: [4.0, 5.5, 0.0], size: [1.4, 0.7, 0.75]}
  - {name: table1, label: table, room: kitchen, pose: [10.0, 5.0, 0.0], size: [1.0, 0.8, 0.75]}
objects:
  - {name: cereal1, label: cerealbox, on: table1, offset: [0.0, 0.0], size: [0.2, 0.07, 0.3]}
robot: {model: pioneer, start: [1.0, 0.9, 0.0]}
"""


@pytest.mark.parametrize("robot", ["pioneer", "pr2"])
def test_a_target_behind_a_door_first_seen_obliquely_is_found(robot: str) -> None:
    """The kitchen's 0.75 m door is first seen from 10 m down the corridor: the grid shows it
    narrower than it is (0.70 m), below the PR2's 0.72 m planning disc (the PR2 gave up
    there, 'the robot needs 0.79 m'); the space behind stays a goal and both robots find
    the cereal box. The PR2 squeezes through with 3.5 cm a side: its path keeps the full
    margin up to the doorway (a diagonal from the corridor at the slim margin clipped the
    jamb, and the keep-out disc there closed the door: found in 6 of seeds 0-7, now 16 of
    seeds 0-15)."""
    spec = EpisodeSpec.from_dict({"target": "cerealbox", "world_file": _OBLIQUE_WORLD,
                                  "robot": robot, "seed": 1, "time_budget_s": 900.0})
    summary = Episode(spec).run()
    assert summary["outcome"] == "found" and summary["correct"], summary["reason"]


@pytest.mark.parametrize("robot", ["pioneer", "pr2"])
def test_a_robot_inside_a_new_keep_out_disc_first_steps_out_of_it(robot: str) -> None:
    """A refused leg that started next to what it touched (a corner the scans had not shown)
    leaves the robot inside the new keep-out disc: it steps straight away from the touched
    point before the next path is planned (else that path starts past the same corner)."""
    sim = open_world(load_spec("office", robot, start=(6.0, 3.2, 0.0)), seed=1)
    try:
        mind, executor, events = _executor(sim, sim)
        touch = (6.0 + mind.config.robot_radius - 0.02, 3.2)  # just ahead of the rim
        blockage = mind.block(touch, sim.clock)
        assert math.dist(sim.pose[:2], touch) < blockage.radius
        executor.driver.back_off(blockage)
        assert math.dist(sim.pose[:2], touch) >= blockage.radius
        assert sim.pose[0] < 6.0 and sim.pose[1] == pytest.approx(3.2, abs=1e-6)
        assert any(k.get("backed_off") == blockage.id for _, k in events)
        far = mind.block((9.0, 3.2), sim.clock)  # a touch well away: nothing to step out of
        before = sim.pose
        executor.driver.back_off(far)
        assert sim.pose == before
    finally:
        sim.world.close()


@pytest.mark.parametrize(("detail", "tried_out"), [("", True), ("explored on the way", False)])
def test_a_placeholder_still_there_after_a_look_from_it_is_tried_out(
        corridor, detail, tried_out) -> None:  # noqa: ANN001
    """The robot reached a placeholder and looked all round, and its frontier is still there:
    a second try from the same spot would see the same, so it is not the nearest placeholder
    (nor a goal) again. A move cut short (the frontier cleared on the way, a blockage) is no
    such evidence and keeps its second try."""
    mind, builder, executor = corridor
    target = next(iter(mind.place_map.placeholders))
    looks: list[int] = []
    executor.drive_to = lambda goal, stop=None: StepOutcome(StepStatus.DONE, detail)
    executor.look_around = lambda: looks.append(1)
    executor.move(target, builder.build())
    assert looks == [1] and target in mind.place_map.placeholders
    limit = builder.config.max_placeholder_tries
    assert (mind.tried_placeholders[target] >= limit) is tried_out
    if tried_out:
        assert executor.nearest_placeholder() != target
