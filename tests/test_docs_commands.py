"""The README's and the docs' examples stay true: every `avs ...` command in their code blocks
parses with the CLI's own argument parser (nothing is run), and every relative link points to a
file that exists. Fast: no episode, no planner, no simulator."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from avs_planner.cli import build_parser

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
DOCS = sorted((ROOT / "docs").glob("*.md"))
# Markdown files whose code blocks hold example commands; every one of them must parse.
COMMAND_FILES = [README, *DOCS, ROOT / "sim" / "README.md"]
LINK_FILES = [README, *DOCS, ROOT / "sim" / "README.md"]

_FENCE = re.compile(r"^\s*(```|~~~)")
_LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)|!\[[^\]]*\]\(([^)\s]+)\)")
_PROGRAMS = {"avs", ".venv/bin/avs"}
_SEPARATORS = {"&&", "||", "|", ";"}


def code_block_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) of every line inside a fenced code block, continuations joined."""
    lines: list[tuple[int, str]] = []
    inside = False
    pending: tuple[int, str] | None = None
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if _FENCE.match(line):
            inside = not inside
            continue
        if not inside:
            continue
        if pending is not None:
            number, line = pending[0], pending[1] + " " + line.strip()
            pending = None
        if line.rstrip().endswith("\\"):
            pending = (number, line.rstrip()[:-1])
            continue
        lines.append((number, line))
    return lines


def avs_commands(path: Path) -> list[tuple[str, list[str]]]:
    """Every `avs ...` / `.venv/bin/avs ...` invocation in the file's code blocks, as
    (where, arguments after the program name). Shell comments are dropped and `&&`, `|`, `;`
    chains are split, so each invocation is checked on its own."""
    found: list[tuple[str, list[str]]] = []
    for number, line in code_block_lines(path):
        try:
            lexer = shlex.shlex(line, posix=True, punctuation_chars=True)
            lexer.whitespace_split = True
            lexer.commenters = "#"
            words = list(lexer)
        except ValueError:
            continue  # not shell (YAML, Python, output)
        segment: list[str] = []
        for word in [*words, ";"]:
            if word in _SEPARATORS:
                if segment and segment[0] in _PROGRAMS:
                    found.append((f"{path.relative_to(ROOT)}:{number}", segment[1:]))
                segment = []
            else:
                segment.append(word)
    return found


COMMANDS = [item for path in COMMAND_FILES if path.exists() for item in avs_commands(path)]


def test_the_readme_shows_commands() -> None:
    readme = [where for where, _ in COMMANDS if where.startswith("README.md")]
    assert len(readme) >= 5, readme


def test_make_run_and_make_test_come_first() -> None:
    first_block = [text for _, text in code_block_lines(README)][:2]
    assert first_block[0].startswith("make run") and first_block[1].startswith("make test")


@pytest.mark.parametrize(("where", "argv"), COMMANDS, ids=[where for where, _ in COMMANDS])
def test_example_command_parses(where: str, argv: list[str]) -> None:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse's way of saying "bad usage"
        pytest.fail(f"{where}: `avs {shlex.join(argv)}` does not parse (exit {exc.code})")
    assert getattr(args, "func", None) is not None, f"{where}: no subcommand in {argv}"


def relative_links(path: Path) -> list[tuple[str, str]]:
    """(where, target) of every link in the file that is not a URL or a page anchor."""
    links: list[tuple[str, str]] = []
    inside = False
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if _FENCE.match(line):
            inside = not inside
            continue
        if inside:
            continue
        for match in _LINK.finditer(line):
            target = match.group(1) or match.group(2)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                continue
            links.append((f"{path.relative_to(ROOT)}:{number}", target.split("#", 1)[0]))
    return links


LINKS = [item for path in LINK_FILES for item in relative_links(path)]


def test_the_readme_links_to_the_docs() -> None:
    targets = {target for where, target in LINKS if where.startswith("README.md")}
    assert {"docs/results.md", "docs/architecture.md", "docs/experiments.md"} <= targets


@pytest.mark.parametrize(("where", "target"), LINKS, ids=[f"{w}->{t}" for w, t in LINKS])
def test_relative_link_points_to_a_file(where: str, target: str) -> None:
    source = ROOT / where.rsplit(":", 1)[0]
    assert (source.parent / target).exists(), f"{where}: link to {target}, which does not exist"


def test_the_link_pattern_sees_links() -> None:
    found = [m.group(1) for m in _LINK.finditer("see [the results](docs/results.md#a) and [x](https://e.org)")]
    assert found == ["docs/results.md#a", "https://e.org"]


def test_every_make_target_the_readme_names_exists() -> None:
    makefile = (ROOT / "Makefile").read_text()
    targets = set(re.findall(r"^([A-Za-z][\w-]*):", makefile, flags=re.MULTILINE))
    named = set(re.findall(r"`make ([a-z][\w-]*)`", README.read_text()))
    named |= {text.split()[1] for _, text in code_block_lines(README) if text.startswith("make ")}
    assert {"run", "test"} <= named
    assert named <= targets, f"README names make targets the Makefile lacks: {named - targets}"
