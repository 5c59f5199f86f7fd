"""Once a plan is found: patience (expansions without a better one) and limits return the
best plan found so far, with `stopped_by` saying why; both engines agree."""

from __future__ import annotations

import json
import math

import pytest

from avs_planner.cli import main
from avs_planner.cp import native
from avs_planner.cp.grounding import GroundingCache
from avs_planner.cp.planner import plan
from avs_planner.cp.search import DEFAULT_PATIENCE, PlanStatus, SearchOptions
from avs_planner.errors import PlanningError
from avs_planner.pddl import read_text
from bench.avs_generator import AvsSize, generate

from .conftest import AVS_DOMAIN

ENGINES = ["python", "native"] if native.AVAILABLE else ["python"]


@pytest.fixture(scope="module")
def late_better():
    """p8, seed 5: a first plan (objective 491.9) after 18 expansions; a better one (368.9)
    only after 2,298 (measured with the default options)."""
    return read_text(AVS_DOMAIN.read_text(), generate(AvsSize(8, 2, 2, 4), 5), "d", "p")


def _run(pproblem, **kw):
    return plan(pproblem, SearchOptions(**kw), cache=GroundingCache())


@pytest.mark.parametrize("engine", ENGINES)
def test_patience_returns_the_first_plan_when_nothing_better_comes(late_better, engine):
    short = _run(late_better, patience=50, engine=engine)
    assert short.solved and short.stopped_by == "patience"
    assert short.objective == pytest.approx(491.865)
    assert short.expanded == 18 + 50 + 1
    assert short.as_json()["stopped_by"] == "patience"


def test_engines_agree_when_patience_stops(late_better):
    if not native.AVAILABLE:
        pytest.skip("native core not built")
    a = _run(late_better, patience=50, engine="python")
    b = _run(late_better, patience=50, engine="native")
    assert [s.label for s in a.plan] == [s.label for s in b.plan]
    assert (a.expanded, a.generated, a.stopped_by) == (b.expanded, b.generated, b.stopped_by)


def test_default_patience_keeps_a_late_improvement(late_better):
    full = _run(late_better)
    assert full.solved and full.stopped_by is None
    assert full.objective == pytest.approx(368.893)
    assert full.expanded - 18 < DEFAULT_PATIENCE


@pytest.mark.parametrize("engine", ENGINES)
def test_a_node_limit_after_a_plan_returns_that_plan(late_better, engine):
    result = _run(late_better, node_limit=100, patience=math.inf, engine=engine)
    assert result.status is PlanStatus.SOLVED and result.stopped_by == "node_limit"
    assert result.objective == pytest.approx(491.865)
    none_yet = _run(late_better, node_limit=5, engine=engine)
    assert none_yet.status is PlanStatus.NODE_LIMIT and not none_yet.plan
    assert none_yet.stopped_by is None


def test_admissible_heuristics_wait_without_limit():
    assert SearchOptions(heuristic="hmax").patience_used == math.inf
    assert SearchOptions().patience_used == DEFAULT_PATIENCE
    assert SearchOptions(patience=7).patience_used == 7
    with pytest.raises(PlanningError, match="patience"):
        SearchOptions(patience=-1).check()


def test_cli_patience_option(tmp_path, capsys):
    domain, problem = tmp_path / "d.pddl", tmp_path / "p.pddl"
    domain.write_text(AVS_DOMAIN.read_text())
    problem.write_text(generate(AvsSize(8, 2, 2, 4), 5))
    assert main(["plan", str(domain), str(problem), "--patience", "50", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "solved" and out["stopped_by"] == "patience"
    assert main(["plan", str(domain), str(problem), "--patience", "50"]) == 0
    assert "; stopped by: patience" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exc:
        main(["plan", str(domain), str(problem), "--patience", "soon"])
    assert exc.value.code != 0
    assert "--patience" in capsys.readouterr().err


@pytest.mark.parametrize("engine", ENGINES)
def test_limits_beyond_any_count_mean_no_limit(late_better, engine):
    """A patience or node limit too large for the C core's int64 is no limit, not a crash."""
    huge = _run(late_better, patience=1e30, node_limit=10**30, engine=engine)
    assert huge.solved and huge.stopped_by is None
    assert huge.objective == pytest.approx(368.893)
