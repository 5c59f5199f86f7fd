"""`avs domain check`: FILE:LINE:COL output, --json, exit codes 0/1, never a traceback."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avs_planner.cli import main

ROOT = Path(__file__).resolve().parents[3]
AVS = ROOT / "domains" / "avs"
DATA = ROOT / "tests" / "avs_planner" / "pddl" / "data"
CASES = json.loads((DATA / "broken.json").read_text())
ACCEPTED = json.loads((DATA / "accepted.json").read_text())


def _broken_files(case: dict, tmp_path: Path) -> tuple[Path, Path, str]:
    files = {
        "domain": (DATA / "base-domain.pddl").read_text(),
        "problem": (DATA / "base-problem.pddl").read_text(),
    }
    also = case.get("also")  # one more replacement, made first
    if also is not None:
        files[also["file"]] = files[also["file"]].replace(also["old"], also["new"])
    broken = files[case["file"]].replace(case["old"], case["new"])
    files[case["file"]] = broken
    index = (broken.rfind if case.get("last") else broken.find)(case["anchor"])
    line = broken.count("\n", 0, index) + 1
    column = index - (broken.rfind("\n", 0, index) + 1) + 1
    paths = {}
    for kind, text in files.items():
        paths[kind] = tmp_path / f"{kind}.pddl"
        paths[kind].write_text(text)
    return paths["domain"], paths["problem"], f"{paths[case['file']]}:{line}:{column}: error: "


def test_the_avs_domain_and_its_problems_pass(capsys: pytest.CaptureFixture[str]) -> None:
    problems = sorted(str(p) for p in (AVS / "problems").glob("*.pddl"))
    assert len(problems) >= 3
    assert main(["domain", "check", str(AVS / "domain.pddl"), *problems]) == 0
    assert ": error: " not in capsys.readouterr().out


@pytest.mark.parametrize("case", CASES, ids=lambda c: c["name"])
def test_broken_input_exits_1_and_points_at_the_mistake(
    case: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    domain, problem, expected = _broken_files(case, tmp_path)
    strict = ["--strict"] if case.get("severity") == "warning" else []
    assert main(["domain", "check", str(domain), str(problem), *strict]) == 1
    out = capsys.readouterr()
    assert any(line.startswith(expected) for line in out.out.splitlines()), out.out
    assert "Traceback" not in out.err


@pytest.mark.parametrize("case", ACCEPTED, ids=lambda c: c["name"])
def test_what_plan_plans_for_passes_the_check(
    case: dict, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = {**case, "anchor": case["new"]}
    domain, problem, _ = _broken_files(case, tmp_path)
    assert main(["domain", "check", str(domain), str(problem)]) == 0
    out = capsys.readouterr()
    assert ": error: " not in out.out and "Traceback" not in out.err
    assert main(["plan", str(domain), str(problem)]) == 0
    out = capsys.readouterr()
    steps = [line for line in out.out.splitlines() if line.startswith("(")]
    assert len(steps) == case["steps"] and "; cost: " in out.out


def test_json_output_is_a_list_of_findings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = next(c for c in CASES if c["name"] == "unknown-predicate")
    domain, problem, _ = _broken_files(case, tmp_path)
    assert main(["domain", "check", str(domain), str(problem), "--json"]) == 1
    findings = json.loads(capsys.readouterr().out)
    assert isinstance(findings, list) and findings
    first = next(f for f in findings if f["code"] == "unknown-predicate")
    assert set(first) == {"file", "line", "column", "severity", "code", "message"}
    assert first["severity"] == "error" and "did you mean 'clear'" in first["message"]


def test_warnings_alone_exit_0(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    domain = (DATA / "base-domain.pddl").read_text()
    domain = domain.replace("(holding ?x - block))", "(holding ?x - block) (spare))")
    (tmp_path / "d.pddl").write_text(domain)
    assert main(["domain", "check", str(tmp_path / "d.pddl")]) == 0
    assert ": warning: predicate 'spare' is never used" in capsys.readouterr().out


def test_goal_already_true_is_a_warning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    problem = (DATA / "base-problem.pddl").read_text().replace("(on a desk)", "(on b desk)")
    (tmp_path / "p.pddl").write_text(problem)
    args = ["domain", "check", str(DATA / "base-domain.pddl"), str(tmp_path / "p.pddl")]
    assert main(args) == 0
    assert "warning: the goal already holds in :init" in capsys.readouterr().out


def test_missing_file_is_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "none.pddl"
    assert main(["domain", "check", str(missing)]) == 1
    assert f"{missing}:1:1: error: cannot read file" in capsys.readouterr().out
    args = ["domain", "check", str(DATA / "base-domain.pddl"), str(missing)]
    assert main(args) == 1
    assert f"{missing}:1:1: error: cannot read file" in capsys.readouterr().out


def test_missing_requirement_is_a_warning_unless_strict(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = next(c for c in CASES if c["name"] == "missing-requirement")
    domain, problem, expected = _broken_files(case, tmp_path)
    assert main(["domain", "check", str(domain), str(problem)]) == 0
    warning = expected.replace(": error: ", ": warning: ")
    assert any(line.startswith(warning) for line in capsys.readouterr().out.splitlines())
    assert main(["domain", "check", str(domain), str(problem), "--strict"]) == 1
    assert any(line.startswith(expected) for line in capsys.readouterr().out.splitlines())


def test_plan_reads_on_and_prints_the_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = next(c for c in CASES if c["name"] == "missing-requirement")
    domain, problem, expected = _broken_files(case, tmp_path)
    assert main(["plan", str(domain), str(problem)]) == 0
    out = capsys.readouterr()
    assert out.err.startswith(expected.replace(": error: ", ": warning: ")), out.err
    assert "; cost:" in out.out
