"""The `avs` entry point itself: help, version, and the never-a-traceback rule."""

from __future__ import annotations

import pytest

from avs_planner.cli import EXIT_BAD_INPUT, main


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert "avs 0.1.0" in capsys.readouterr().out


def test_no_command_prints_help_and_fails(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == EXIT_BAD_INPUT
    assert "usage: avs" in capsys.readouterr().out


def test_unknown_command_is_usage_error() -> None:
    with pytest.raises(SystemExit) as exc:
        main(["no-such-command"])
    assert exc.value.code == EXIT_BAD_INPUT


def test_every_command_has_a_description_in_its_help() -> None:
    """`avs CMD --help` says what the command does, beyond its one-line summary."""
    import argparse

    from avs_planner.cli import build_parser

    def walk(parser: argparse.ArgumentParser, path: list[str]):  # noqa: ANN202
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from walk(sub, [*path, name])
                return
        yield path, parser

    leaves = list(walk(build_parser(), []))
    assert len(leaves) >= 10
    for path, parser in leaves:
        assert parser.description and len(parser.description) > 40, " ".join(path)


def test_simulate_without_out_never_overwrites_an_earlier_run(tmp_path, monkeypatch) -> None:
    from avs_planner.cli import main

    monkeypatch.chdir(tmp_path)
    args = ["simulate", "--scenario", "a", "--seed", "1", "--time-budget", "5", "--json"]
    for _ in range(2):
        assert main(args) in (0, 2, 3)
    runs = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert runs == ["office-cerealbox", "office-cerealbox-2"]
    assert all((tmp_path / "runs" / r / "summary.json").exists() for r in runs)
