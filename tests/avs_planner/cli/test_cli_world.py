"""`avs world generate`: YAML to stdout or a file, same seed same file, exit 1 on bad input."""

from __future__ import annotations

from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.cli.world import _STYLES
from sim.generate import STYLES, generate_world
from sim.world_file import load_world_spec


def test_generate_writes_the_yaml_to_stdout(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["world", "generate", "--seed", "4", "--style", "apartment", "--rooms", "5"]) == 0
    out = capsys.readouterr().out
    assert out == generate_world(4, "apartment", rooms=5).yaml()


def test_generate_writes_a_file_that_sim_loads(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "lab.yaml"
    args = ["world", "generate", "--seed", "9", "--style", "lab", "--surprise", "0.5",
            "--robot", "pr2", "--out", str(out)]
    assert main(args) == 0
    assert f"wrote {out}: lab_9" in capsys.readouterr().out
    spec = load_world_spec(out)
    assert spec.name == "lab_9" and spec.robot.model == "pr2"
    assert out.read_text() == generate_world(9, "lab", surprise=0.5, robot="pr2").yaml()


@pytest.mark.parametrize(("args", "message"), [
    (["--rooms", "99"], "rooms: style office takes 3 to 12 rooms off its corridor, got 99"),
    (["--style", "apartment", "--rooms", "9"], "style apartment takes 3 to 8 rooms"),
    (["--surprise", "-0.1"], "surprise: expected a share in [0, 1], got -0.1"),
    (["--seed", "-3"], "seed: expected a non-negative integer, got -3"),
    (["--style", "castle"], "invalid choice: 'castle'"),
    (["--day", "-1"], "day: expected a non-negative integer, got -1"),
    (["--day", "2", "--move", "1.5"], "move: expected a probability in [0, 1], got 1.5"),
    (["--day", "2", "--doors", "-0.5"], "doors: expected a probability in [0, 1], got -0.5"),
])
def test_bad_input_exits_1_with_a_clear_message(
        args: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["world", "generate", *(["--seed", "1"] if "--seed" not in args else []), *args]
    code = _exit_code(argv)
    err = capsys.readouterr().err
    assert code == 1 and message in err and "Traceback" not in err


def _exit_code(argv: list[str]) -> int:
    """`main`'s return value, or the code of the SystemExit argparse raises on a usage error."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code or 0)


def test_an_unwritable_output_is_bad_input(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "missing" / "w.yaml"
    assert main(["world", "generate", "--seed", "1", "--out", str(out)]) == 1
    assert "cannot write" in capsys.readouterr().err


def test_the_style_choices_are_the_generators() -> None:
    assert _STYLES == STYLES


def test_generate_writes_a_later_day_of_the_building(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["world", "generate", "--seed", "5", "--day", "3", "--move", "0.5",
                 "--doors", "0.2"]) == 0
    out = capsys.readouterr().out
    assert out == generate_world(5, "office", day=3, move=0.5, doors=0.2).yaml()
    assert out != generate_world(5, "office").yaml()
    assert out.splitlines()[0].endswith("--day 3 --move 0.5 --doors 0.2")
    assert main(["world", "generate", "--seed", "5", "--day", "0", "--move", "0.9"]) == 0
    assert capsys.readouterr().out == generate_world(5, "office").yaml()
