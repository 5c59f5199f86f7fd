"""Placement tables: the `moved` variant differs from the default one only where its header
says, its worlds load, and the default table's worlds are what they were."""

from __future__ import annotations

from collections import Counter

import pytest

from sim.errors import GenerationError
from sim.generate import generate_world
from sim.generation.table import DEFAULT_TABLE, TABLES, load_table, placement_table

MOVED = {"cup", "book", "stapler"}
# the moved table's rows of its moved labels, as its header describes them:
# (category, label, support, weight, unusual)
DOCUMENTED = {
    ("office", "cup", "desk", 2.0, False), ("office", "cup", "table", 1.0, False),
    ("office", "cup", "shelf", 1.0, True),
    ("meeting_room", "cup", "table", 3.0, False),
    ("meeting_room", "stapler", "table", 2.0, False),
    ("meeting_room", "stapler", "desk", 1.0, False),
    ("kitchen", "book", "shelf", 3.0, False), ("kitchen", "book", "counter", 2.0, False),
    ("kitchen", "book", "table", 2.0, False), ("kitchen", "stapler", "counter", 1.0, True),
    ("living_room", "book", "shelf", 3.0, False), ("living_room", "book", "table", 2.0, False),
    ("living_room", "cup", "table", 2.0, False), ("living_room", "cup", "shelf", 1.0, True),
    ("living_room", "stapler", "table", 1.0, True),
    ("bathroom", "cup", "counter", 1.0, False), ("bathroom", "stapler", "counter", 1.0, True),
    ("bathroom", "book", "counter", 1.0, True),
}


def _rows(table, labels=None):
    return Counter((p.category, p.label, p.support, p.weight, p.unusual)
                   for p in table.placements if labels is None or p.label in labels)


def test_the_moved_table_differs_from_the_default_only_in_its_moved_labels() -> None:
    default, moved = placement_table(), placement_table("moved")
    others = {p.label for p in default.placements} - MOVED
    assert _rows(moved, others) == _rows(default, others)
    assert (moved.styles, moved.rooms, moved.object_sizes, moved.supports) == (
        default.styles, default.rooms, default.object_sizes, default.supports)
    assert set(_rows(moved, MOVED)) == DOCUMENTED and max(_rows(moved, MOVED).values()) == 1


def test_the_moved_labels_are_kept_out_of_their_commonsense_rooms() -> None:
    """The shift the header documents: no cups in kitchens, no books in offices or meeting
    rooms, no staplers in offices."""
    moved = placement_table("moved")
    where = {(p.label, p.category) for p in moved.placements}
    assert not where & {("cup", "kitchen"), ("book", "office"), ("book", "meeting_room"),
                        ("stapler", "office")}
    default = {(p.label, p.category) for p in placement_table().placements}
    assert {("cup", "kitchen"), ("book", "office"), ("stapler", "office")} <= default


def test_moved_worlds_load_and_follow_their_table() -> None:
    for seed in range(400, 412):
        world = generate_world(seed, "office", table="moved")
        spec = world.spec()
        assert spec.name == f"office_{seed}_moved" and world.table == "moved"
        assert world.yaml().splitlines()[0].endswith("--table moved")
        for obj in spec.objects:
            room = spec.room(spec.furniture_named(obj.on).room).category
            assert (obj.label, room) not in {("cup", "kitchen"), ("book", "office"),
                                            ("stapler", "office")}, (seed, obj.name)
        assert generate_world(seed, "office", table="moved").yaml() == world.yaml()


def test_the_default_table_by_name_is_the_same_world_and_differs_from_moved() -> None:
    for seed in (0, 5, 401):
        plain = generate_world(seed, "office")
        assert generate_world(seed, "office", table=DEFAULT_TABLE).yaml() == plain.yaml()
        assert "--table" not in plain.yaml() and plain.data["name"] == f"office_{seed}"
    moved = generate_world(401, "office", table="moved")
    plain = generate_world(401, "office")
    assert moved.data["rooms"] == plain.data["rooms"]  # same layout: the table moves objects
    assert moved.data["furniture"] == plain.data["furniture"]
    assert moved.data["objects"] != plain.data["objects"]


def test_an_unknown_table_is_refused_naming_the_argument() -> None:
    with pytest.raises(GenerationError, match="table: unknown placement table 'tilted'"):
        generate_world(1, table="tilted")
    assert set(TABLES) == {"default", "moved"}


def test_an_overlay_row_of_a_label_it_does_not_move_is_refused(tmp_path) -> None:
    (tmp_path / "placement.yaml").write_text(TABLES["default"].read_text(encoding="utf-8"))
    bad = tmp_path / "placement-bad.yaml"
    bad.write_text("base: placement.yaml\nmoved: [cup]\n"
                   "placements:\n  kitchen:\n    usual:\n      - [book, shelf, 1]\n")
    with pytest.raises(GenerationError, match="label 'book' is not one of the moved labels"):
        load_table(bad)

