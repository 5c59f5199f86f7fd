"""The DT as the active visual search paper uses it: MOVE costs along the robot's own
paths (through the door, not through the wall), unreachable cones left out, one goal reward R
from the loop's config, and a support searched on it and in it where the knowledge puts the
label."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from avs_planner.cli import main
from avs_planner.dt import TravelCosts, ViewCone
from avs_planner.episode import dt_search
from avs_planner.episode.dt_search import PathLengths, ViewConeSearch, travel_costs
from avs_planner.episode.state_builder import SearchTask, StateBuilder
from avs_planner.episode.viewcones import CameraModel, ConeSet, aim_height, support_cones
from avs_planner.harness.sim_robot import Seen
from conceptual_map.conceptual import RelatedSpace
from conceptual_map.metric import OccupancyGrid
from conceptual_map.metric.path_planning import PathResult, PathStatus
from conceptual_map.metric.synthetic import rooms_world

# two rooms side by side, the wall between them at x = 3 with a 0.92 m door at y = 2, and a
# closed room beyond the second (no door)
ROOMS = [(0.0, 0.0, 3.0, 4.0), (3.0, 0.0, 6.0, 4.0), (6.0, 0.0, 8.0, 4.0)]
DOOR = (3.0, 2.0, 0.92)
WEST, EAST, SHUT = (2.0, 1.0), (4.0, 1.0), (7.0, 2.0)


@pytest.fixture(scope="module")
def executor() -> SimpleNamespace:
    """What the DT's costs read of the executor's skills: the context's robot pose, the
    mind's grid and planning radius, the body's speeds, and the driver's squeeze (none
    here)."""
    world = rooms_world(ROOMS, [DOOR])
    grid = OccupancyGrid(origin=(-1.0, -1.0), size=(10.0, 6.0))
    for pose in [(1.0, 1.0, 0.0), (2.0, 3.0, 3.1), (4.5, 2.0, 0.0), (5.0, 3.3, 2.0),
                 (5.0, 0.7, 1.0), (7.0, 2.0, 0.0), (7.0, 1.0, 2.0)]:
        grid.integrate_scan(world.laser(pose, beams=1440))
    mind = SimpleNamespace(grid=grid, config=SimpleNamespace(robot_radius=0.3),
                           body=SimpleNamespace(linear_speed=0.5, angular_speed=1.0))
    events: list[tuple[str, dict]] = []
    context = SimpleNamespace(mind=mind, robot=SimpleNamespace(pose=(*WEST, 0.0)),
                              emit=lambda type_, **fields: events.append((type_, fields)))
    driver = SimpleNamespace(squeeze=lambda a, b: PathResult(PathStatus.NO_PATH, (), math.inf, 0))
    return SimpleNamespace(context=context, driver=driver, events=events)


def test_travel_between_cones_either_side_of_a_wall_follows_the_door(executor) -> None:
    lengths = PathLengths(executor.context.mind, executor.driver.squeeze)
    metres = lengths(WEST, EAST)
    straight = math.dist(WEST, EAST)
    via_door = math.dist(WEST, DOOR[:2]) + math.dist(DOOR[:2], EAST)
    assert metres > straight + 0.5  # not through the wall
    assert via_door - 0.05 <= metres <= via_door * 1.08  # round through the door
    assert lengths(EAST, WEST) == metres and lengths(WEST, SHUT) == math.inf
    cones = [ViewCone("w", (*WEST, 0.0), 0.3), ViewCone("e", (*EAST, 0.0), 0.3)]
    start = (1.0, 1.0, 0.0)
    costs = travel_costs(start, cones, lengths, speed=0.5, turn_speed=1.0)
    straight_costs = TravelCosts.from_poses(start, cones)
    assert costs.between[0][1] == pytest.approx(metres / 0.5)
    assert costs.between[0][1] > straight_costs.between[0][1] + 1.0
    assert costs.from_start[1] > straight_costs.from_start[1]
    assert costs.from_start[0] == pytest.approx(straight_costs.from_start[0], abs=0.05)


def test_cones_no_path_reaches_are_left_out_of_the_session(executor) -> None:
    cones = (ViewCone("c-0", (*EAST, 0.0), 0.3), ViewCone("c-1", (*SHUT, 0.0), 0.3))
    search = ViewConeSearch(executor.context, executor.driver, None, None, {}, "cup", "in",
                            "room2")
    kept, travel = search._reachable(ConeSet(cones, 0.8, 0.75))
    assert [c.id for c in kept.cones] == ["c-0"] and kept.coverage == 0.8
    assert len(travel.from_start) == 1 and travel.from_start[0] > math.dist(WEST, EAST) / 0.5
    assert executor.events[-1] == ("belief", {"unreachable_cones": ["c-1"]})


def test_reward_option_reaches_the_dt(tmp_path, monkeypatch) -> None:
    rewards = []
    session = dt_search.DTSession

    def recording(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        rewards.append(kwargs["rewards"])
        return session(*args, **kwargs)

    monkeypatch.setattr(dt_search, "DTSession", recording)
    # Fig. 3d: the run that searches with the DT (on every development seed)
    code = main(["simulate", "--scenario", "d", "--seed", "0", "--option", "reward=777",
                 "--out", str(tmp_path)])
    assert code == 0 and rewards
    assert {(r.miss_penalty, r.false_confirm_penalty) for r in rewards} == {(777.0, 777.0)}


def test_a_support_search_looks_in_it_as_well_as_on_it(corridor) -> None:
    """A cup may be in a shelf (the default knowledge's `in` relation, and none `on`):
    the shelf is one of the cup's supports, its cones aim into it, a detection inside it
    counts, and a search thins the cup's count in it."""
    mind, _, executor = corridor
    place = mind.place_map.current_place
    x, y = mind.place_map.places[place].position
    shelf = mind.add_object("shelf", (x + 0.8, y, 0.8))  # a 1.6 m shelf
    knowledge = mind.cmap.knowledge
    assert knowledge.support_relations("cup")["shelf"] == ("in",)
    cup = StateBuilder(mind, SearchTask("cup"))
    assert "shelf" in cup.supports
    values = cup.build().values
    assert max(v for k, v in values.items() if k[:3] == ("p-obj-on", "cup", "shelf")) > 0.5
    assert aim_height(1.6, ("in",)) == pytest.approx(1.2)
    assert aim_height(0.75, ("on",)) == 0.75
    camera = CameraModel(height=1.4, hfov=math.radians(60), detect_range=4.0)
    on = support_cones(mind, shelf, 0.4, camera, "on")
    inside = support_cones(mind, shelf, 0.4, camera, "in", relations=("in",))
    assert inside.cones and all(a.head[1] > b.head[1] for a, b in zip(
        on.cones, inside.cones, strict=True))  # tilted further down: into the shelf
    search = executor.view_cone_search("cup", "on", shelf.id)
    assert search._inside(Seen(1, "cup", (x + 0.8, y, 0.9), 0.9), "on", shelf.id)
    assert not search._inside(Seen(2, "cup", (x + 0.8, y, 2.3), 0.9), "on", shelf.id)
    book = executor.view_cone_search("book", "on", shelf.id)  # a book is on a shelf
    assert not book._inside(Seen(3, "book", (x + 0.8, y, 0.9), 0.9), "on", shelf.id)
    assert book._inside(Seen(4, "book", (x + 0.8, y, 1.7), 0.9), "on", shelf.id)
    before = mind.cmap.p_object_at("cup", RelatedSpace("in", shelf.id))
    assert executor.location_belief("cup", "on", shelf.id) == pytest.approx(before)
    search._searched("cup", "on", shelf.id, 0.9)
    assert mind.cmap.p_object_at("cup", RelatedSpace("in", shelf.id)) < 0.5 * before
