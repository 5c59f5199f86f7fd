"""Days of one generated building: objects move, doors toggle, the rest stays; day 0 unchanged."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.errors import GenerationError
from sim.generate import STYLES, generate_world
from sim.generation.days import _candidates
from sim.generation.furnish import Piece
from sim.generation.layout import DoorPlan, Layout, RoomPlan, connected
from sim.generation.objects import SmallObject
from sim.generation.table import placement_table
from sim.scene import World

DAY0 = Path(__file__).parent / "data" / "day0"
EDGE = 0.02  # sim.generation.objects.EDGE


@pytest.mark.parametrize("name", ["gen-office-7", "gen-apartment-318", "gen-lab-12"])
def test_day_zero_is_the_generator_output_before_days_existed(name: str) -> None:
    _, style, seed = name.split("-")
    expected = (DAY0 / f"{name}.yaml").read_text(encoding="utf-8")
    assert generate_world(int(seed), style).yaml() == expected
    assert generate_world(int(seed), style, day=0).yaml() == expected
    assert generate_world(int(seed), style, day=0, move=0.9, doors=0.5).yaml() == expected


def test_a_day_is_deterministic_and_comes_from_the_day_before() -> None:
    a = generate_world(21, "office", day=4, move=0.5, doors=0.3)
    b = generate_world(21, "office", day=4, move=0.5, doors=0.3)
    assert a.yaml() == b.yaml()
    assert "--day 4 --move 0.5 --doors 0.3" in a.yaml().splitlines()[0]
    days = [generate_world(21, "office", day=k, move=0.5) for k in range(4)]
    assert len({d.yaml() for d in days}) == 4  # objects moved every day
    # the other arguments of a day after another's world change the building itself
    assert generate_world(22, "office", day=4, move=0.5).data != a.data


def test_move_zero_moves_nothing_and_furniture_walls_and_start_never_move() -> None:
    for seed, style in ((3, "office"), (4, "apartment"), (5, "lab")):
        day0 = generate_world(seed, style)
        still = generate_world(seed, style, day=6, move=0.0)
        assert still.data == day0.data
        later = generate_world(seed, style, day=6, move=0.6, doors=0.4)
        for key in ("rooms", "furniture", "robot", "size"):
            assert later.data[key] == day0.data[key]
        assert [o["name"] for o in later.data["objects"]] == \
            [o["name"] for o in day0.data["objects"]]
        assert [o["label"] for o in later.data["objects"]] == \
            [o["label"] for o in day0.data["objects"]]
        assert later.labels_present() == day0.labels_present()


def test_move_one_moves_every_object_that_has_another_support_and_keeps_them_legal() -> None:
    table = placement_table()
    for seed in range(12):
        style = STYLES[seed % len(STYLES)]
        day0 = generate_world(seed, style)
        for day in (1, 3):
            world = generate_world(seed, style, day=day, move=1.0)
            spec = world.spec()  # sim's loader: on supports, inside the tops, in rooms
            assert {o.name for o in spec.objects} == {o["name"] for o in day0.data["objects"]}
            _assert_tops_hold(world)
        after = generate_world(seed, style, day=1, move=1.0)
        for old, new in zip(day0.data["objects"], after.data["objects"], strict=True):
            if old["on"] == new["on"]:  # stays only where no other support can take it
                assert not _other_supports(table, day0, old), (seed, old)
        with World(after.spec(), seed):
            pass  # PyBullet builds it


def _parts(world) -> tuple[Layout, list[Piece], list[SmallObject]]:  # noqa: ANN001
    d = world.data
    rooms = tuple(RoomPlan(r["name"], r["category"], tuple(r["rect"]), 0) for r in d["rooms"])
    doors = tuple(DoorPlan(tuple(x["rooms"]), tuple(x["at"]), x["width"], "x", x["open"])
                  for x in d["doors"])
    pieces = [Piece(f["name"], f["label"], f["room"], tuple(f["pose"]), tuple(f["size"]),
                    (0.0, 0.0, 0.0, 0.0)) for f in d["furniture"]]  # boxes: not needed here
    objects = [SmallObject(o["name"], o["label"], o["on"], tuple(o["offset"]), tuple(o["size"]),
                           o["name"] in world.surprises) for o in d["objects"]]
    return Layout(tuple(d["size"]), rooms, doors), pieces, objects


def _other_supports(table, world, obj) -> bool:  # noqa: ANN001
    layout, pieces, _ = _parts(world)
    small = SmallObject(obj["name"], obj["label"], obj["on"], tuple(obj["offset"]),
                        tuple(obj["size"]), False)
    kinds = _candidates(table, layout, pieces, small)
    return bool(kinds[False] or kinds[True])


def _assert_tops_hold(world) -> None:  # noqa: ANN001
    """Every object inside its support's top (EDGE in) and apart from the others there."""
    furniture = {f["name"]: f for f in world.data["furniture"]}
    on: dict[str, list[tuple[float, float, float, float]]] = {}
    for o in world.data["objects"]:
        top = furniture[o["on"]]
        assert top["label"] in ("table", "desk", "counter", "shelf")
        (dx, dy), (sx, sy, _) = o["offset"], o["size"]
        assert abs(dx) + sx / 2 <= top["size"][0] / 2 - EDGE + 1e-6, o
        assert abs(dy) + sy / 2 <= top["size"][1] / 2 - EDGE + 1e-6, o
        box = (dx - sx / 2, dy - sy / 2, dx + sx / 2, dy + sy / 2)
        for other in on.setdefault(o["on"], []):
            assert (box[2] <= other[0] or other[2] <= box[0] or box[3] <= other[1]
                    or other[3] <= box[1]), (o, other)
        on[o["on"]].append(box)


def test_every_object_moves_with_probability_move() -> None:
    moves = total = 0
    for seed in range(20):
        days = [generate_world(seed, STYLES[seed % 3], day=k, move=0.2) for k in (0, 1)]
        for a, b in zip(days[0].data["objects"], days[1].data["objects"], strict=True):
            total += 1
            moves += a["on"] != b["on"]
    assert 0.12 < moves / total < 0.28, (moves, total)


def test_doors_toggle_and_every_room_stays_reachable() -> None:
    toggled = 0
    for seed in range(15):
        style = STYLES[seed % 3]
        day0 = generate_world(seed, style)
        for day in (1, 3, 8):
            world = generate_world(seed, style, day=day, move=0.0, doors=0.5)
            names = [r["name"] for r in world.data["rooms"]]
            doors = [DoorPlan(tuple(d["rooms"]), tuple(d["at"]), d["width"], "x", d["open"])
                     for d in world.data["doors"]]
            assert connected(names, doors), (seed, day)
            assert [(d["rooms"], d["at"]) for d in world.data["doors"]] == \
                [(d["rooms"], d["at"]) for d in day0.data["doors"]]
            toggled += sum(a["open"] != b["open"]
                           for a, b in zip(day0.data["doors"], world.data["doors"], strict=True))
            world.spec()
    assert toggled > 0
    assert generate_world(4, "office", day=5, move=0.0).data["doors"] == \
        generate_world(4, "office").data["doors"]  # doors 0: they stay as generated


@pytest.mark.parametrize(("kwargs", "key"), [({"day": -1}, "day"), ({"day": 1.5}, "day"),
                                             ({"day": True}, "day"), ({"move": 1.2}, "move"),
                                             ({"move": "x"}, "move"), ({"doors": -0.1}, "doors")])
def test_bad_day_arguments_name_the_argument(kwargs: dict, key: str) -> None:
    with pytest.raises(GenerationError, match=rf"^{key}: "):
        generate_world(1, "office", **kwargs)
