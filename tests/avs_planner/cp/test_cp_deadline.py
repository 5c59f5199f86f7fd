"""One deadline bounds a whole planning call: grounding, the greedy phase and the restarts.

The clock is injected (`Deadline(clock=...)`) and advanced by the test, a fixed amount per
grounding or per search call, so each assertion counts phases, never wall-clock seconds.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

import avs_planner.cp.anytime as anytime_module
import avs_planner.cp.planner as planner_module
from avs_planner.cli import main
from avs_planner.cp.anytime import AnytimeRun
from avs_planner.cp.deadline import Deadline
from avs_planner.cp.search import PlanResult, PlanStatus, SearchOptions, search
from tests.avs_planner.cp.conftest import AVS_DOMAIN, CORRIDOR


class FakeClock:
    """Seconds that pass only when the test says so."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class Searches:
    """Every search call of the planner: when it started (fake clock), the time it was
    given; each call advances the clock by `cost` seconds."""

    def __init__(self, clock: FakeClock, cost: float) -> None:
        self.clock, self.cost = clock, cost
        self.calls: list[tuple[float, float | None]] = []
        self.results: list[PlanResult] = []

    def install(self, monkeypatch: pytest.MonkeyPatch) -> Searches:
        monkeypatch.setattr(anytime_module, "search", self)
        monkeypatch.setattr(planner_module, "search", self)
        return self

    def __call__(self, task, options=None, symmetries=None) -> PlanResult:  # noqa: ANN001
        self.calls.append((self.clock.now, options.timeout_s))
        result = search(task, options, symmetries)
        self.results.append(result)
        self.clock.now += self.cost
        return result


def _slow_grounding(monkeypatch: pytest.MonkeyPatch, clock: FakeClock, seconds: float) -> None:
    real = planner_module.ground

    def ground(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        task = real(*args, **kwargs)
        clock.now += seconds
        return task

    monkeypatch.setattr(planner_module, "ground", ground)


@pytest.mark.parametrize("anytime", [False, True], ids=["weighted", "anytime"])
def test_grounding_that_uses_up_the_time_ends_the_call_before_any_search(
        corridor, monkeypatch: pytest.MonkeyPatch, anytime: bool) -> None:
    clock = FakeClock()
    _slow_grounding(monkeypatch, clock, 11.0)
    searches = Searches(clock, 1.0).install(monkeypatch)
    options = SearchOptions(timeout_s=10.0, anytime=anytime)
    result = planner_module.plan(corridor, options,
                                 deadline=Deadline.from_now(10.0, clock))
    assert searches.calls == []
    assert result.status is PlanStatus.TIMEOUT and result.expanded == 0 and not result.plan


def test_the_weighted_search_gets_the_time_grounding_left(
        corridor, monkeypatch: pytest.MonkeyPatch) -> None:
    clock = FakeClock()
    _slow_grounding(monkeypatch, clock, 4.0)
    searches = Searches(clock, 1.0).install(monkeypatch)
    result = planner_module.plan(corridor, SearchOptions(timeout_s=10.0),
                                 deadline=Deadline.from_now(10.0, clock))
    assert result.solved
    assert searches.calls == [(clock.now - 1.0, pytest.approx(6.0))]


def test_the_deadline_during_improvement_returns_the_best_plan_so_far(
        corridor, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each search "takes" one second. Unbounded, the schedule runs its greedy phase and
    four restarts; with 3.5 s (grounding included) it starts exactly the four searches that
    begin before the deadline, each with the time left, and keeps the best of their plans."""
    clock = FakeClock()
    unbounded = Searches(clock, 1.0).install(monkeypatch)
    planner_module.plan(corridor, SearchOptions(anytime=True),
                        deadline=Deadline.from_now(None, clock))
    assert len(unbounded.calls) == 1 + len(anytime_module.WEIGHTS)

    start = clock.now
    bounded = Searches(clock, 1.0).install(monkeypatch)
    result = planner_module.plan(corridor, SearchOptions(anytime=True, timeout_s=3.5),
                                 deadline=Deadline.from_now(3.5, clock))
    assert [at - start for at, _ in bounded.calls] == [0.0, 1.0, 2.0, 3.0]
    assert [given for _, given in bounded.calls] == pytest.approx([3.5, 2.5, 1.5, 0.5])
    assert result.solved and result.stopped_by == "timeout"
    assert result.objective == min(r.objective for r in bounded.results if r.solved)
    assert result.extra["anytime"][0]["weight"] == "greedy"


def test_no_greedy_round_starts_after_the_deadline(
        corridor, monkeypatch: pytest.MonkeyPatch) -> None:
    """A greedy phase that finds nothing (a node limit of one expansion per round): with
    2.5 s, three rounds start (at 0, 1 and 2 s) and the call ends with no plan."""
    clock = FakeClock()
    searches = Searches(clock, 1.0).install(monkeypatch)
    options = SearchOptions(anytime=True, timeout_s=2.5, node_limit=1)
    result = planner_module.plan(corridor, options, deadline=Deadline.from_now(2.5, clock))
    assert [at for at, _ in searches.calls] == [100.0, 101.0, 102.0]
    assert all(r.status is PlanStatus.NODE_LIMIT for r in searches.results)
    assert result.status in (PlanStatus.TIMEOUT, PlanStatus.NODE_LIMIT) and not result.plan


def test_improving_plans_counts_grounding_against_the_run_s_deadline(
        corridor, monkeypatch: pytest.MonkeyPatch) -> None:
    """The unified-planning anytime engine's path: the run made before grounding."""
    clock = FakeClock()
    _slow_grounding(monkeypatch, clock, 5.0)
    searches = Searches(clock, 1.0).install(monkeypatch)
    options = SearchOptions(anytime=True, timeout_s=5.0)
    run = AnytimeRun(deadline=Deadline.from_now(5.0, clock))
    assert list(planner_module.improving_plans(corridor, options, run)) == []
    assert searches.calls == []
    assert run.result(options).status is PlanStatus.TIMEOUT


def test_the_deadline_reads_its_clock() -> None:
    clock = FakeClock()
    deadline = Deadline.from_now(2.0, clock)
    assert deadline.left() == 2.0 and not deadline.passed()
    clock.now += 2.0
    assert deadline.left() == 0.0 and deadline.passed()
    assert Deadline.from_now(None, clock).left() is None
    assert not replace(deadline, timeout_s=None).passed()


def test_avs_plan_says_when_no_plan_was_found_in_time(capsys: pytest.CaptureFixture) -> None:
    """A timeout shorter than any grounding: no search, exit 3, said on stderr."""
    assert main(["plan", str(AVS_DOMAIN), str(CORRIDOR), "--timeout", "1e-9"]) == 3
    captured = capsys.readouterr()
    assert "; status: timeout" in captured.out
    assert "avs plan: no plan within 1e-09 s" in captured.err
