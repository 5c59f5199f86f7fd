"""Closed-loop sessions: the behaviours the issue's "Done when" asks for, for every policy."""

import pytest

from avs_planner.dt import (
    POLICIES,
    ActionKind,
    DetectorModel,
    DtInputError,
    DTSession,
    DtSessionError,
    DTStatus,
    SearchBudget,
    ViewCone,
)
from avs_planner.dt.domain import look, move

BUDGET = SearchBudget(num_sims=200)


def _drive(session, detections):
    """Run a session; `detections(cone, k)` says whether the k-th look at `cone` detects."""
    looks: dict[int, int] = {}
    while True:
        action = session.next_action()
        if session.finished:
            return session.result
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            k = looks.get(action.cone, 0)
            looks[action.cone] = k + 1
            session.update(action, detections(action.cone, k), detection=f"obj@{action.cone}")
        else:
            session.update(action)


@pytest.mark.parametrize("policy", sorted(POLICIES))
def test_one_certain_cone_is_confirmed_after_one_look(policy):
    session = DTSession([ViewCone("table", (2.0, 0.0, 0.0), 1.0)], DetectorModel(),
                        (0.0, 0.0, 0.0), policy=policy, budget=BUDGET)
    result = _drive(session, lambda cone, k: True)
    assert result.status is DTStatus.CONFIRMED
    assert result.cone_id == "table" and result.detection == "obj@0"
    assert [s.action.kind for s in result.trace] == [ActionKind.MOVE,
                                                      ActionKind.PROCESS_VIEW_CONE]
    assert result.probability == pytest.approx(1.0)


@pytest.mark.parametrize("policy", ["pouct", "exact", "greedy"])
def test_high_prior_with_false_negatives_looks_again_before_rejecting(policy):
    session = DTSession([ViewCone("table", (2.0, 0.0, 0.0), 0.9)], DetectorModel(0.2, 0.05),
                        (0.0, 0.0, 0.0), policy=policy, budget=BUDGET)
    result = _drive(session, lambda cone, k: False)
    looks = [s for s in result.trace if s.action.kind is ActionKind.PROCESS_VIEW_CONE]
    assert result.status is DTStatus.REJECTED
    assert len(looks) >= 2
    # rejection reports what is left: 0.9 * 0.2^k / (0.9 * 0.2^k + 0.1 * 0.95^k)
    k = len(looks)
    assert result.probability == pytest.approx(0.9 * 0.2**k / (0.9 * 0.2**k + 0.1 * 0.95**k))


def test_no_false_negatives_means_one_look_is_enough():
    session = DTSession([ViewCone("table", (2.0, 0.0, 0.0), 0.9)], DetectorModel(0.0, 0.05),
                        (0.0, 0.0, 0.0), policy="pouct", budget=BUDGET)
    result = _drive(session, lambda cone, k: False)
    assert result.status is DTStatus.REJECTED
    assert sum(s.action.kind is ActionKind.PROCESS_VIEW_CONE for s in result.trace) == 1
    assert result.probability == pytest.approx(0.0)


@pytest.mark.parametrize("policy", sorted(POLICIES))
def test_zero_prior_rejects_without_moving(policy):
    cones = [ViewCone("a", (2.0, 0.0, 0.0), 0.0), ViewCone("b", (0.0, 3.0, 1.0), 0.0)]
    session = DTSession(cones, DetectorModel(), (0.0, 0.0, 0.0), policy=policy, budget=BUDGET)
    result = _drive(session, lambda cone, k: True)
    assert result.status is DTStatus.REJECTED
    assert result.trace == () and result.cost == 0.0 and result.probability == 0.0


def test_pouct_searches_the_likely_cone_and_confirms():
    cones = [ViewCone("far-unlikely", (6.0, 0.0, 0.0), 0.05),
             ViewCone("near-likely", (1.0, 0.0, 0.0), 0.7),
             ViewCone("mid", (3.0, 3.0, 0.0), 0.15)]
    session = DTSession(cones, policy="pouct", budget=BUDGET, seed=3)
    result = _drive(session, lambda cone, k: cone == 1)
    assert result.trace[0].action == move(1)
    assert result.status is DTStatus.CONFIRMED and result.cone_id == "near-likely"


def test_same_seed_same_decisions():
    cones = [ViewCone(f"c{i}", (float(i), float(i % 3), 0.0), 0.15) for i in range(5)]

    def actions(seed):
        session = DTSession(cones, policy="pouct", budget=BUDGET, seed=seed)
        return [s.action for s in _drive(session, lambda cone, k: cone == 4).trace]

    assert actions(7) == actions(7)


def test_trace_records_costs_and_beliefs():
    cones = [ViewCone("a", (3.0, 4.0, 0.0), 0.6)]
    session = DTSession(cones, policy="greedy", sensing_cost=2.0)
    result = _drive(session, lambda cone, k: k == 1)
    assert result.status is DTStatus.CONFIRMED
    assert result.trace[0].cost == pytest.approx(10.0)  # 5 m at 0.5 m/s
    assert [s.cost for s in result.trace[1:]] == [2.0, 2.0]
    assert result.cost == pytest.approx(14.0)
    assert len(result.decision_times_s) == len(result.trace) + 1
    assert sum(result.trace[-1].belief) == pytest.approx(1.0)


def test_driving_errors_are_clear():
    session = DTSession([ViewCone("a", (1.0, 0.0, 0.0), 0.5)], policy="greedy")
    with pytest.raises(DtSessionError, match="robot is at cone -1"):
        session.update(look(0), True)
    with pytest.raises(DtSessionError, match="no view cone with index 3"):
        session.update(move(3))
    session.update(move(0))
    with pytest.raises(DtSessionError, match="needs a detection result"):
        session.update(look(0))
    with pytest.raises(DtSessionError, match="only the cone just seen"):
        session.update(session.next_action().__class__(ActionKind.CONFIRM, 0))


def test_unknown_policy_lists_the_choices():
    with pytest.raises(DtInputError, match="choose one of"):
        DTSession([ViewCone("a", (1.0, 0.0, 0.0), 0.5)], policy="random")


def test_step_budget_forces_a_stop():
    session = DTSession([ViewCone("a", (1.0, 0.0, 0.0), 0.99)], DetectorModel(0.5, 0.05),
                        policy="greedy", horizon=3)
    result = _drive(session, lambda cone, k: False)
    assert len(result.trace) == 3 and result.status is DTStatus.REJECTED
