"""What lay behind a vanished placeholder, read from the robot's own grid and place map."""

from __future__ import annotations

from dataclasses import dataclass, field

from avs_planner.episode.placeholder_outcomes import PlaceholderOutcomes
from conceptual_map.conceptual import ConceptualMap
from conceptual_map.metric import OccupancyGrid
from conceptual_map.places.model import Change, EntityKind, MapEvent, Placeholder


@dataclass
class FakePlaceMap:
    """The two things the outcomes read of a place map: its placeholders and rooms, and
    which room's floor holds a point (here: rooms are x-intervals of a free strip)."""

    placeholders: dict[str, Placeholder] = field(default_factory=dict)
    rooms: dict[str, object] = field(default_factory=dict)
    extents: dict[str, tuple[float, float]] = field(default_factory=dict)

    def room_at(self, grid, point, reach=1.0, nearest_place=True):  # noqa: ANN001, ANN201
        for room, (lo, hi) in self.extents.items():
            if lo <= point[0] < hi:
                return room
        return None


def _grid() -> OccupancyGrid:
    """10 x 2 m: free along y in [0.5, 1.5], unknown beyond x = 4 until a test sees it."""
    grid = OccupancyGrid((0.0, 0.0), (10.0, 2.0), 0.05)
    m = grid.model
    grid.logodds[...] = 0
    grid.logodds[:80, 10:30] = m.clamp_min
    grid._touch()
    return grid


def _see(grid: OccupancyGrid, x0: float, x1: float, occupied: bool = False) -> None:
    m = grid.model
    grid.logodds[int(x0 / 0.05):int(x1 / 0.05), 10:30] = m.clamp_max if occupied else m.clamp_min
    grid._touch()


def _setup():
    cmap = ConceptualMap()
    cmap.add_place("p1", "room1")
    cmap.add_placeholder("ph1", "room1", open_space_m2=20.0, p_door=0.0)
    place_map = FakePlaceMap()
    place_map.placeholders["ph1"] = Placeholder("ph1", (3.5, 1.0), (4.0, 1.0), 1.0, 20.0, "p1",
                                                None)
    place_map.rooms["room1"] = object()
    place_map.extents["room1"] = (0.0, 4.0)
    return cmap, place_map, _grid(), PlaceholderOutcomes()


def _vanish(cmap, place_map, outcomes, grid):  # noqa: ANN001, ANN202
    before = outcomes.snapshot(cmap, place_map)
    gone = place_map.placeholders.pop("ph1")
    cmap.remove_placeholder("ph1")
    event = MapEvent(EntityKind.PLACEHOLDER, Change.VANISHED, "ph1", gone, 1.0)
    return outcomes.update(before, [event], cmap, place_map, grid)


def test_a_frontier_onto_a_new_room_is_a_new_room_once_the_room_is_known():
    cmap, place_map, grid, outcomes = _setup()
    assert _vanish(cmap, place_map, outcomes, grid) == 0  # behind it: still unknown
    assert "ph1" in outcomes.pending
    _see(grid, 4.0, 8.0)
    assert outcomes.update(outcomes.snapshot(cmap, place_map), [], cmap, place_map, grid) == 0
    assert "ph1" in outcomes.pending  # free, but no room's yet (beyond a door not passed)
    place_map.rooms["room2"] = object()
    place_map.extents["room2"] = (4.0, 8.0)
    assert outcomes.update(outcomes.snapshot(cmap, place_map), [], cmap, place_map, grid) == 1
    assert cmap.calibration.outcomes["open"][0][1] == 1
    assert not outcomes.pending


def test_a_frontier_onto_its_own_room_or_a_wall_led_to_no_new_room():
    for wall in (False, True):
        cmap, place_map, grid, outcomes = _setup()
        _see(grid, 4.0, 8.0, occupied=wall)
        place_map.extents["room1"] = (0.0, 8.0)  # the room goes on behind the frontier
        assert _vanish(cmap, place_map, outcomes, grid) == 1
        assert [y for _, y in cmap.calibration.outcomes["open"]] == [0]


def test_a_room_known_before_the_placeholder_vanished_is_not_new():
    cmap, place_map, grid, outcomes = _setup()
    _see(grid, 4.0, 8.0)
    cmap.add_place("p2", "room2")
    place_map.rooms["room2"] = object()
    place_map.extents["room2"] = (4.0, 8.0)  # a loop back into a room the robot knew
    assert _vanish(cmap, place_map, outcomes, grid) == 1
    assert cmap.calibration.outcomes["open"][0][1] == 0


def test_outcomes_lower_what_the_remaining_placeholders_promise():
    cmap, place_map, grid, outcomes = _setup()
    cmap.calibration.apply = True  # the switching strategy's `calibrate_placeholders`
    cmap.add_placeholder("ph2", "room1", open_space_m2=20.0, p_door=0.0)
    before = cmap.placeholder_category("ph2")["none"]
    _see(grid, 4.0, 8.0, occupied=True)
    _vanish(cmap, place_map, outcomes, grid)
    assert cmap.placeholder_category("ph2")["none"] > before


def test_the_switching_option_decides_whether_the_correction_is_used(
        corridor, switching_loop) -> None:  # noqa: ANN001
    from avs_planner.episode.trace import Trace
    from avs_planner.strategies.switching.loop import LoopConfig

    mind, builder, executor = corridor
    switching_loop(builder, executor, Trace(lambda: 0.0))
    assert mind.cmap.calibration.apply is False
    switching_loop(builder, executor, Trace(lambda: 0.0), LoopConfig(calibrate_placeholders=True))
    assert mind.cmap.calibration.apply is True
