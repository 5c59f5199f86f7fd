"""`avs plan`: text and JSON output, exit codes."""

from __future__ import annotations

import json
from pathlib import Path

from avs_planner.cli import main

ROOT = Path(__file__).resolve().parents[3]
DOMAIN = str(ROOT / "domains/avs/domain.pddl")
CORRIDOR = str(ROOT / "domains/avs/problems/corridor.pddl")


def test_plan_json_has_the_contract_keys(capsys):
    assert main(["plan", DOMAIN, CORRIDOR, "--json", "--reward", "500"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("status", "plan", "cost", "probability", "objective", "planning_time_s",
                "expanded"):
        assert key in out
    assert out["status"] == "solved"
    assert out["plan"][0] == "(assume-leads-to-room place1 kitchen new-room1)"
    assert out["objective"] == out["cost"] + 500 * (1 - out["probability"])


def test_plan_text_one_action_per_line(capsys):
    assert main(["plan", DOMAIN, CORRIDOR]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("(assume-leads-to-room")
    assert any(line.startswith("; objective:") for line in lines)


def test_exit_codes(capsys, tmp_path):
    assert main(["plan", DOMAIN, str(tmp_path / "missing.pddl")]) == 1
    assert main(["plan", DOMAIN, CORRIDOR, "--weight", "0"]) == 1
    assert main(["plan", DOMAIN, CORRIDOR, "--min-success", "0.9"]) == 2
    assert main(["plan", DOMAIN, CORRIDOR, "--node-limit", "1"]) == 3
    text = Path(CORRIDOR).read_text()
    for goal in ("(and (reported cerealbox) (visited place1) (not (visited place1)))",
                 "(and (reported cerealbox) (connected place0 place3))"):
        bad = tmp_path / "unsolvable.pddl"
        bad.write_text(text.replace("(:goal (reported cerealbox))", f"(:goal {goal})"))
        capsys.readouterr()
        assert main(["plan", DOMAIN, str(bad), "--json"]) == 2
        assert json.loads(capsys.readouterr().out)["status"] == "unsolvable"


def test_a_limit_with_hadd_or_hmax_suggests_ff(capsys):
    for heuristic in ("hadd", "hmax"):
        capsys.readouterr()
        assert main(["plan", DOMAIN, CORRIDOR, "--node-limit", "1", "--heuristic",
                     heuristic]) == 3
        err = capsys.readouterr().err
        assert f"with --heuristic {heuristic}; ff (the default)" in err
    assert main(["plan", DOMAIN, CORRIDOR, "--node-limit", "1"]) == 3
    assert capsys.readouterr().err == ""  # ff itself: nothing to suggest


def test_threads_option_gives_the_same_plan(capsys):
    plans = []
    for threads in ("1", "2"):
        assert main(["plan", DOMAIN, CORRIDOR, "--json", "--threads", threads]) == 0
        out = json.loads(capsys.readouterr().out)
        plans.append((out["plan"], out["expanded"]))
    assert plans[0] == plans[1]
