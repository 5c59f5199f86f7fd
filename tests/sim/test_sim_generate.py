"""The floor-plan generator: valid worlds, deterministic, reachable, and surprising on purpose."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from conceptual_map.knowledge import Knowledge, load_knowledge
from sim.errors import GenerationError
from sim.generate import STYLES, GeneratedWorld, generate_world
from sim.generation.table import CATEGORIES, placement_table
from sim.render import render_world
from sim.scene import World
from sim.walls import door_openings, wall_segments
from sim.world_checks import shared_wall
from sim.world_spec import DoorSpec, FurnitureSpec, RobotSpec, RoomSpec, WorldSpec

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
LIKELY, UNLIKELY = 0.1, 0.05  # relation lambdas: usual placements at least, unusual at most
PR2_RADIUS = 0.34


@pytest.fixture(scope="module")
def worlds() -> list[GeneratedWorld]:
    """100 seeds, the styles taken in turn."""
    return [generate_world(seed, STYLES[seed % len(STYLES)]) for seed in range(100)]


@pytest.fixture(scope="module")
def specs(worlds: list[GeneratedWorld]) -> list[WorldSpec]:
    return [w.spec() for w in worlds]


@pytest.fixture(scope="module")
def knowledge() -> Knowledge:
    return load_knowledge()


def test_hundred_seeds_pass_the_world_checks(specs: list[WorldSpec]) -> None:
    assert len(specs) == 100  # spec() raised for none: parsed and checked by sim's loader
    for spec in specs:
        assert spec.room_at(*spec.robot.start[:2]) is not None
        assert spec.furniture and spec.objects and len(spec.doors) >= len(spec.rooms)


@pytest.mark.parametrize(("seed", "style"), [(0, "office"), (1, "apartment"), (2, "lab")])
def test_pybullet_loads_and_the_pr2_drives_through_every_open_door(seed: int, style: str) -> None:
    spec = generate_world(seed, style, robot="pr2").spec()
    World(spec, seed).close()  # the robot adapter refuses a start where the pr2 collides
    for door in spec.doors:
        before, after = _across(spec, door)
        start = replace(spec, robot=RobotSpec("pr2", (*before, 0.0)))
        with World(start, seed) as world:
            blocked = world.robot.blocked_by([after])
        assert (blocked is None) == door.open, f"{spec.name} {door.label}: {blocked}"


def _across(spec: WorldSpec, door: DoorSpec, reach: float = 0.6) -> tuple[tuple[float, float],
                                                                         tuple[float, float]]:
    """Points `reach` metres either side of a door, on the line through its centre."""
    a, b = (spec.room(name) for name in door.rooms)
    assert a is not None and b is not None
    x, y = door.at
    vertical = abs(x - a.rect[0]) < 1e-6 or abs(x - a.rect[2]) < 1e-6
    step = (reach, 0.0) if vertical else (0.0, reach)
    p, q = (x - step[0], y - step[1]), (x + step[0], y + step[1])
    return (p, q) if a.contains(*p) else (q, p)


def test_same_seed_same_world_and_different_seeds_differ() -> None:
    first, again = generate_world(7, "office"), generate_world(7, "office")
    assert first.yaml() == again.yaml() and first.surprises == again.surprises
    texts = {generate_world(seed, "office").yaml() for seed in range(10)}
    assert len(texts) == 10
    assert generate_world(7, "lab").yaml() != first.yaml()


@pytest.mark.parametrize("style", STYLES)
def test_each_style_has_its_spine_categories_and_room_counts(style: str) -> None:
    rule = placement_table().styles[style]
    for seed in range(8):
        spec = generate_world(seed, style).spec()
        spine, *rooms = spec.rooms
        assert spine.name == rule.spine and spine.category == "corridor"
        assert rule.default_rooms[0] <= len(rooms) <= rule.default_rooms[1]
        categories = [r.category for r in rooms]
        assert set(categories) <= set(rule.categories)
        assert set(rule.required[:len(rooms)]) <= set(categories)
        assert all(categories.count(c) <= n for c, n in rule.at_most.items())


@pytest.mark.parametrize(("style", "rooms"),
                         [("office", 3), ("office", 12), ("apartment", 8), ("lab", 10)])
def test_rooms_k_is_honoured(style: str, rooms: int) -> None:
    rule = placement_table().styles[style]
    for seed in range(3):
        spec = generate_world(seed, style, rooms=rooms).spec()
        assert len(spec.rooms) == rooms + 1  # the spine is extra
        categories = [r.category for r in spec.rooms[1:]]
        assert all(categories.count(c) <= n for c, n in rule.at_most.items())


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"rooms": 13}, "style office takes 3 to 12 rooms off its corridor, got 13"),
    ({"rooms": 2, "style": "apartment"}, "style apartment takes 3 to 8 rooms"),
    ({"style": "castle"}, "unknown style 'castle'"),
    ({"surprise": 1.5}, "surprise: expected a share in [0, 1], got 1.5"),
    ({"seed": -1}, "seed: expected a non-negative integer, got -1"),
    ({"robot": "turtlebot"}, "unknown model 'turtlebot'"),
])
def test_bad_arguments_are_clear_errors(kwargs: dict, message: str) -> None:
    args = {"seed": 1, **kwargs}
    with pytest.raises(GenerationError, match=message.replace("[", r"\[").replace("]", r"\]")):
        generate_world(**args)


def test_every_room_is_reachable_from_the_start_through_open_doors(
        specs: list[WorldSpec]) -> None:
    for spec in specs:
        links = [_rooms_at(spec, door.at) for door in spec.doors if door.open]
        assert all(len(pair) == 2 for pair in links), spec.name
        start = spec.room_at(*spec.robot.start[:2])
        reached, frontier = {start.name}, [start.name]
        while frontier:
            here = frontier.pop()
            for pair in links:
                for other in pair - {here} if here in pair else ():
                    if other not in reached:
                        reached.add(other)
                        frontier.append(other)
        assert reached == {r.name for r in spec.rooms}, spec.name


def test_the_pr2_can_drive_from_the_start_into_every_room_and_up_to_every_object(
        specs: list[WorldSpec]) -> None:
    """On a 5 cm grid of where the pr2's centre may stand (walls, closed doors, furniture)."""
    for spec in specs[:30]:
        gx, gy, reached = _reached(spec)
        assert len(_entered(spec, gx, gy, reached)) == len(spec.rooms), spec.name
        for obj in spec.objects:
            near = _box_distance(gx, gy, _bbox(spec.furniture_named(obj.on))) <= PR2_RADIUS + 0.6
            assert np.any(reached & near), f"{spec.name}: {obj.name} out of reach"


def test_the_free_cell_check_sees_closed_doors(specs: list[WorldSpec]) -> None:
    spec = specs[0]
    shut = replace(spec, doors=tuple(replace(d, open=False) for d in spec.doors))
    for world, rooms in ((spec, len(spec.rooms)), (shut, 1)):
        assert len(_entered(world, *_reached(world))) == rooms


def _reached(spec: WorldSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid x, grid y, and the cells the pr2's centre reaches from the start."""
    xs, ys, free = _pr2_free_cells(spec)
    labels, _ = ndimage.label(free)
    sx, sy, _ = spec.robot.start
    gx, gy = np.meshgrid(xs, ys)
    return gx, gy, labels == labels[np.abs(ys - sy).argmin(), np.abs(xs - sx).argmin()]


def _entered(spec: WorldSpec, gx: np.ndarray, gy: np.ndarray,
             reached: np.ndarray) -> list[str]:
    return [r.name for r in spec.rooms if np.any(reached & (gx > r.rect[0]) & (gx < r.rect[2])
                                                  & (gy > r.rect[1]) & (gy < r.rect[3]))]


def _pr2_free_cells(spec: WorldSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    xs = np.arange(0.025, spec.size[0], 0.05)
    ys = np.arange(0.025, spec.size[1], 0.05)
    gx, gy = np.meshgrid(xs, ys)
    half = spec.wall_thickness / 2
    boxes = [(s.line - half, s.lo, s.line + half, s.hi) if s.axis == "x"
             else (s.lo, s.line - half, s.hi, s.line + half) for s in wall_segments(spec)]
    boxes += [(s.line - 0.02, s.lo, s.line + 0.02, s.hi) if s.axis == "x"
              else (s.lo, s.line - 0.02, s.hi, s.line + 0.02)
              for s in (o.segment for o in door_openings(spec) if not o.open)]
    boxes += [_bbox(item) for item in spec.furniture]
    free = np.ones(gx.shape, dtype=bool)
    for box in boxes:
        free &= _box_distance(gx, gy, box) >= PR2_RADIUS
    return xs, ys, free


def _bbox(item: FurnitureSpec) -> tuple[float, float, float, float]:
    xs, ys = zip(*item.footprint(), strict=True)
    return (min(xs), min(ys), max(xs), max(ys))


def _box_distance(gx: np.ndarray, gy: np.ndarray, box: tuple[float, ...]) -> np.ndarray:
    dx = np.maximum(np.maximum(box[0] - gx, 0.0), gx - box[2])
    dy = np.maximum(np.maximum(box[1] - gy, 0.0), gy - box[3])
    return np.hypot(dx, dy)


def _rooms_at(spec: WorldSpec, point: tuple[float, float]) -> set[str]:
    """Rooms whose border passes through `point` (a door joins exactly two)."""
    return {r.name for r in spec.rooms if r.contains(*point) and not r.contains(*point, 0.01)}


def test_some_doors_are_closed_and_some_rooms_are_entered_through_others(
        specs: list[WorldSpec]) -> None:
    for spec in specs:
        spine = spec.rooms[0].name
        assert any(not d.open for d in spec.doors), spec.name
        inner = [r for r in spec.rooms[1:] if not any(
            {spine, r.name} == set(d.rooms) for d in spec.doors)]
        assert inner, spec.name
        assert all(0.8 - 1e-9 <= d.width <= 1.2 + 1e-9 for d in spec.doors)


def test_doors_keep_apart_and_clear_of_wall_ends(specs: list[WorldSpec]) -> None:
    for spec in specs:
        spans = [_span(spec, d) for d in spec.doors]
        for i, (line, lo, hi) in enumerate(spans):
            for other_line, other_lo, other_hi in spans[:i]:
                assert line != other_line or hi <= other_lo or other_hi <= lo, spec.name
        for door, (_, lo, hi) in zip(spec.doors, spans, strict=True):
            _, _, wall_lo, wall_hi = shared_wall(*(spec.room(n) for n in door.rooms))
            assert lo >= wall_lo + 0.3 - 1e-6 and hi <= wall_hi - 0.3 + 1e-6, spec.name


def _span(spec: WorldSpec, door: DoorSpec) -> tuple[tuple[str, float], float, float]:
    """(wall line, low end, high end) of a door opening."""
    axis, line, _, _ = shared_wall(*(spec.room(n) for n in door.rooms))
    along = door.at[1] if axis == "x" else door.at[0]
    return (axis, round(line, 6)), along - door.width / 2, along + door.width / 2


def test_furniture_leaves_the_way_through_every_door_free(specs: list[WorldSpec]) -> None:
    for spec in specs:
        for door in spec.doors:
            before, after = _across(spec, door, reach=0.8)
            lane = _lane(before, after, door.width / 2)
            for item in spec.furniture:
                xs, ys = zip(*item.footprint(), strict=True)
                assert (max(xs) <= lane[0] or min(xs) >= lane[2] or max(ys) <= lane[1]
                        or min(ys) >= lane[3]), f"{spec.name}: {item.name} blocks {door.label}"


def _lane(p: tuple[float, float], q: tuple[float, float], half: float) -> tuple[float, ...]:
    if abs(p[0] - q[0]) < 1e-9:
        return (p[0] - half, min(p[1], q[1]), p[0] + half, max(p[1], q[1]))
    return (min(p[0], q[0]), p[1] - half, max(p[0], q[0]), p[1] + half)


def test_the_start_fits_the_larger_robot(specs: list[WorldSpec]) -> None:
    for spec in specs:
        x, y, _ = spec.robot.start
        room = spec.room_at(x, y)
        assert room.contains(x, y, PR2_RADIUS + spec.wall_thickness / 2), spec.name
        for item in spec.furniture:
            xs, ys = zip(*item.footprint(), strict=True)
            dx = max(min(xs) - x, 0.0, x - max(xs))
            dy = max(min(ys) - y, 0.0, y - max(ys))
            assert math.hypot(dx, dy) >= PR2_RADIUS, f"{spec.name}: start at {item.name}"


def test_small_objects_lie_inside_their_support_top(specs: list[WorldSpec]) -> None:
    supports = placement_table().supports
    for spec in specs:
        for obj in spec.objects:
            top = spec.furniture_named(obj.on)
            assert top.label in supports
            assert abs(obj.offset[0]) + obj.size[0] / 2 <= top.size[0] / 2 + 1e-9
            assert abs(obj.offset[1]) + obj.size[1] / 2 <= top.size[1] / 2 + 1e-9


def test_the_surprise_share_is_roughly_honoured(worlds: list[GeneratedWorld]) -> None:
    placed = sum(len(w.data["objects"]) for w in worlds)
    surprising = sum(len(w.surprises) for w in worlds)
    assert 0.21 <= surprising / placed <= 0.29
    for share in (0.0, 1.0):
        for seed in range(5):
            world = generate_world(seed, "office", surprise=share)
            assert len(world.surprises) == share * len(world.data["objects"])
    half = [generate_world(seed, "apartment", surprise=0.5) for seed in range(30)]
    ratio = sum(len(w.surprises) for w in half) / sum(len(w.data["objects"]) for w in half)
    assert 0.42 <= ratio <= 0.58


def test_unusual_placements_are_rated_unlikely_by_the_knowledge(
        worlds: list[GeneratedWorld], specs: list[WorldSpec], knowledge: Knowledge) -> None:
    for p in placement_table().placements:
        lam = _relation(knowledge, p.label, p.support, p.category)
        assert lam <= UNLIKELY if p.unusual else lam >= LIKELY, p
    for world, spec in zip(worlds, specs, strict=True):
        for obj in spec.objects:
            support = spec.furniture_named(obj.on)
            category = spec.room(support.room).category
            lam = _relation(knowledge, obj.label, support.label, category)
            if obj.name in world.surprises:
                assert lam <= UNLIKELY, (spec.name, obj.name)
            else:
                assert lam >= LIKELY, (spec.name, obj.name)


def _relation(knowledge: Knowledge, label: str, support: str, category: str) -> float:
    lam = knowledge.relation_lambda_of(label, "on", support)
    return float(lam[knowledge.category_index(category)])


def test_categories_and_labels_are_the_knowledge_files(
        specs: list[WorldSpec], knowledge: Knowledge) -> None:
    table = placement_table()
    assert tuple(table.styles) == STYLES
    assert set(CATEGORIES) <= set(knowledge.categories)
    assert set(table.rooms) | {"corridor"} <= set(CATEGORIES)
    furniture = {f.label for rule in table.rooms.values() for f in rule.furniture}
    assert furniture | set(table.object_sizes) | table.supports <= knowledge.labels
    for spec in specs:
        assert {r.category for r in spec.rooms} <= set(CATEGORIES)
        assert {i.label for i in (*spec.furniture, *spec.objects)} <= knowledge.labels


def test_targets_are_present_labels_and_one_absent_label(worlds: list[GeneratedWorld]) -> None:
    vocabulary = set(placement_table().object_labels)
    for world in worlds:
        present = set(world.labels_present())
        assert present == {o["label"] for o in world.data["objects"]}
        first, second, absent = world.targets(rng_seed=world.seed)
        assert first != second and {first, second} <= present
        assert absent in vocabulary - present
        assert world.targets(rng_seed=world.seed) == [first, second, absent]
    with pytest.raises(GenerationError, match="cannot pick 99 present"):
        worlds[0].targets(rng_seed=0, present=99)


@pytest.mark.parametrize(("seed", "style"), [(3, "office"), (4, "apartment")])
def test_generated_worlds_render(seed: int, style: str, tmp_path: Path) -> None:
    out = render_world(generate_world(seed, style).spec(), tmp_path / "world.png")
    data = out.read_bytes()
    assert data.startswith(PNG_MAGIC) and len(data) > 10_000


def test_rooms_differ_in_size_and_aspect(specs: list[WorldSpec]) -> None:
    rooms: list[RoomSpec] = [r for spec in specs for r in spec.rooms[1:]]
    areas = [(r.rect[2] - r.rect[0]) * (r.rect[3] - r.rect[1]) for r in rooms]
    aspects = [(r.rect[2] - r.rect[0]) / (r.rect[3] - r.rect[1]) for r in rooms]
    assert max(areas) / min(areas) > 3 and min(aspects) < 0.7 and max(aspects) > 1.3


def test_the_yaml_header_regenerates_the_world() -> None:
    world = generate_world(11, "apartment", surprise=0.4)
    header = world.yaml().splitlines()[0]
    rooms = len(world.data["rooms"]) - 1
    assert header.endswith(f"--seed 11 --style apartment --rooms {rooms} --surprise 0.4 "
                           "--robot pioneer")
    assert generate_world(11, "apartment", rooms=rooms, surprise=0.4).yaml() == world.yaml()
