"""Top-down rendering and the `avs sim` command line."""

from __future__ import annotations

from pathlib import Path

import pytest

from avs_planner.cli import main
from sim.render import category_colours, render_world
from sim.world_file import load_world_spec

DATA = Path(__file__).parent / "data"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("name", ["office", "flap_two_rooms", "qsr_desks"])
def test_builtin_world_renders(name: str, tmp_path: Path) -> None:
    out = render_world(load_world_spec(name), tmp_path / f"{name}.png")
    data = out.read_bytes()
    assert data.startswith(PNG_MAGIC) and len(data) > 10_000


def test_rooms_are_coloured_by_category() -> None:
    colours = category_colours(load_world_spec("office"))
    assert set(colours) == {"kitchen", "office", "corridor"}
    assert len(set(colours.values())) == 3


def test_cli_render_writes_the_png(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "office.png"
    assert main(["sim", "render", "--world", "office", "--out", str(out)]) == 0
    assert out.read_bytes().startswith(PNG_MAGIC)
    assert f"wrote {out}" in capsys.readouterr().out


def test_cli_render_of_a_broken_world_names_the_entry(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    world = DATA / "broken_door_off_wall.yaml"
    out = tmp_path / "x.png"
    assert main(["sim", "render", "--world", str(world), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "doors[0] (corridor/kitchen): door at (2, 4.1) is not on the shared wall" in err
    assert "Traceback" not in err and not out.exists()


def test_cli_render_rejects_a_non_png_output(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "render", "--world", "office", "--out", "office.jpg"]) == 1
    assert "expected a .png file" in capsys.readouterr().err


def test_cli_check_prints_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "check", "--world", "qsr_desks", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"name": "qsr_desks"' in out and '"model": "pioneer"' in out


def test_render_with_a_trajectory_and_pose(tmp_path: Path) -> None:
    spec = load_world_spec("office")
    path = [(6.0, 3.2), (2.0, 3.25), (2.0, 5.0)]
    plain = render_world(spec, tmp_path / "plain.png").read_bytes()
    drawn = render_world(spec, tmp_path / "tour.png", (2.0, 5.0, 1.57), path).read_bytes()
    assert drawn.startswith(PNG_MAGIC) and drawn != plain
