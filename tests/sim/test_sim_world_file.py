"""World files: built-ins load and validate, broken files name the offending entry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sim.errors import WorldFileError
from sim.rays import ranges_along
from sim.scene import World, load_world
from sim.walls import door_openings, wall_segments
from sim.world_file import builtin_worlds, load_world_spec

DATA = Path(__file__).parent / "data"

BROKEN = {
    "unknown_key": ["rooms[1] (kitchen)", "unknown key 'colour'"],
    "overlapping_rooms": ["rooms[1] (kitchen)", "overlaps room corridor"],
    "door_off_wall": ["doors[0] (corridor/kitchen)", "door at (2, 4.1) is not on the shared wall"],
    "door_no_shared_wall": ["doors[1] (kitchen/office)", "share no wall"],
    "door_too_wide": ["doors[0] (corridor/kitchen)", "does not fit in the shared wall"],
    "object_outside": ["objects[1] (mug1)", "outside every room"],
    "object_floating": ["objects[0] (cereal1)", "floating", "table1"],
    "object_in_furniture": ["objects[1] (mug1)", "intersects furniture table1"],
    "furniture_in_wall": ["furniture[0] (table1)", "overlaps a wall of room kitchen"],
    "furniture_overlap": ["furniture[1] (counter1)", "overlaps furniture table1"],
    "unknown_room_ref": ["furniture[0] (table1)", "no room named 'garage'"],
    "bad_robot_model": ["robot.model", "unknown model 'turtlebot'"],
    "robot_start_collides": ["robot.start", "collides with mug1"],
    "duplicate_name": ["objects[1] (table1)", "already used by furniture[0] (table1)"],
    "bad_vector": ["size", "expected a list of 2 numbers"],
    "yaml_syntax": ["broken_yaml_syntax.yaml:6:5", "YAML error: expected ','"],
    "duplicate_key": ["broken_duplicate_key.yaml:4:1", "duplicate key 'size'"],
}


def test_the_three_builtin_worlds_exist() -> None:
    assert {"office", "flap_two_rooms", "qsr_desks"} <= set(builtin_worlds())


@pytest.mark.parametrize("name", ["office", "flap_two_rooms", "qsr_desks"])
def test_builtin_world_loads_and_validates(name: str) -> None:
    with load_world(name, seed=0) as world:
        assert world.spec.name == name
        assert world.detectables and world.walls
        assert world.robot.room() is not None


def test_office_matches_seed_003() -> None:
    spec = load_world_spec("office")
    assert spec.size == (12.0, 8.0)
    assert {r.name for r in spec.rooms} == {"kitchen", "office1", "office2", "corridor"}
    placed = {o.label: spec.room_at(*spec.object_pose(o)[:2]).name for o in spec.objects}
    assert placed["cerealbox"] == "kitchen"
    assert placed["stapler"] == "office2"
    assert placed["whiteboardmarker"] == "office1"
    cereal = next(o for o in spec.objects if o.label == "cerealbox")
    assert spec.furniture_named(cereal.on).label == "table"
    assert all(0.85 <= d.width <= 0.95 for d in spec.doors)


def test_valid_base_of_the_broken_files_loads() -> None:
    load_world(DATA / "valid_base.yaml").close()


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_broken_world_names_the_entry(case: str) -> None:
    path = DATA / f"broken_{case}.yaml"
    with pytest.raises(WorldFileError) as exc:
        World(load_world_spec(path)).close()
    message = str(exc.value)
    assert message.startswith(str(path))
    for fragment in BROKEN[case]:
        assert fragment in message


def test_unknown_world_name_lists_builtins() -> None:
    with pytest.raises(WorldFileError, match="built-ins: ") as exc:
        load_world_spec("no_such_world")
    listed = str(exc.value).split("built-ins: ", 1)[1]
    for name in ("flap_two_rooms", "office", "qsr_desks"):
        assert name in listed


def test_on_key_is_not_a_yaml_boolean(tmp_path: Path) -> None:
    text = (DATA / "valid_base.yaml").read_text().replace("on: table1", "on: off", 1)
    path = tmp_path / "w.yaml"
    path.write_text(text)
    with pytest.raises(WorldFileError, match="no furniture named 'off'"):
        load_world_spec(path)


def test_doors_cut_openings_in_the_shared_wall() -> None:
    spec = load_world_spec(DATA / "valid_base.yaml")
    walls_on_y4 = sorted((w.lo, w.hi) for w in wall_segments(spec) if (w.axis, w.line) == ("y", 4))
    # the corridor's border runs from 0 to 8; the kitchen door cuts it at 1.55..2.45
    assert walls_on_y4 == [(0.0, pytest.approx(1.55)), (pytest.approx(2.45), 8.0)]
    openings = door_openings(spec)
    assert [(o.segment.lo, o.segment.hi) for o in openings][0] == (1.55, 2.45)


def test_door_opening_in_the_scene_is_as_wide_as_the_file_says() -> None:
    with load_world("office") as world:  # kitchen door: centre (2.0, 4.0), width 0.9
        along_wall = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        gaps = ranges_along(world.client, np.array([2.0, 4.0, 1.0]), along_wall, 3.0)
        assert gaps == pytest.approx([0.45, 0.45])
        world.set_door_open(0, False)
        assert not world.door_is_open(0)
        across = ranges_along(world.client, np.array([2.0, 3.5, 1.0]),
                              np.array([[0.0, 1.0, 0.0]]), 3.0)
        assert across[0] == pytest.approx(0.5 - 0.02)  # the closed door panel is 4 cm thick
