"""Closed-loop multi-label sessions: the modes' stopping rules, per-label results, the step
budget, and clear errors when driven wrongly."""

import pytest

from avs_planner.dt import (
    DETECTED,
    NOT_DETECTED,
    ActionKind,
    DetectorModel,
    DtInputError,
    DtSessionError,
    LabelStatus,
    LabelTarget,
    MultiLabelSession,
    MultiObservation,
    ViewCone,
)
from avs_planner.dt.multi import MULTI_POLICIES
from avs_planner.dt.multi.domain import confirm_label, look_at, move_to, reject_label

CONES = [ViewCone("table", (2.0, 0.0, 0.0), 0.0), ViewCone("shelf", (0.0, 3.0, 1.0), 0.0),
         ViewCone("desk", (4.0, 4.0, 0.0), 0.0)]


def _targets(detector=None):
    detector = detector or DetectorModel(0.2, 0.05)
    return [LabelTarget("cup", (0.6, 0.1, 0.1), detector),
            LabelTarget("book", (0.1, 0.6, 0.1), detector),
            LabelTarget("stapler", (0.1, 0.1, 0.5), detector)]


def _drive(session, where):
    """Run a session; each label is detected exactly where `where` puts it."""
    terminals = []
    while not session.finished:
        action = session.next_action()
        if action.terminal:
            terminals.append(action)
            continue
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            seen = {label: where.get(label) == action.cone for label in session.problem.labels}
            session.update(action, seen, detections={k: f"{k}@{action.cone}" for k, v in
                                                     seen.items() if v})
        else:
            session.update(action)
    return session.result, terminals


@pytest.mark.parametrize("policy", sorted(MULTI_POLICIES))
def test_any_stops_at_the_first_confirm(policy):
    horizon = 6 if policy == "exact" else 0
    session = MultiLabelSession(CONES, _targets(DetectorModel(0.0, 0.0)), mode="any",
                                policy=policy, horizon=horizon)
    result, terminals = _drive(session, {"cup": 0, "book": 1, "stapler": 2})
    assert len(terminals) == 1 and terminals[0].kind is ActionKind.CONFIRM
    confirmed = [r for r in result.labels.values() if r.status is LabelStatus.CONFIRMED]
    assert len(confirmed) == 1 and confirmed[0].label == terminals[0].label
    assert {r.status for r in result.labels.values()} == {LabelStatus.CONFIRMED,
                                                          LabelStatus.DROPPED}
    assert session.next_action() == terminals[0]  # finished: the last action again
    with pytest.raises(DtSessionError, match="has finished"):
        session.update(move_to(0))


def test_all_needs_every_label_decided():
    session = MultiLabelSession(CONES, _targets(DetectorModel(0.0, 0.0)))
    where = {"cup": 0, "book": 1, "stapler": 2}
    decided = set()
    while not session.finished:
        action = session.next_action()
        if action.terminal:
            decided.add(action.label)
            assert session.finished is (decided == set(where))
            continue
        seen = ({label: where[label] == action.cone for label in where}
                if action.kind is ActionKind.PROCESS_VIEW_CONE else None)
        session.update(action, seen)
    result = session.result
    for label, cone in where.items():
        assert result.labels[label].status is LabelStatus.CONFIRMED
        assert result.labels[label].cone_id == CONES[cone].id
        assert result.labels[label].probability == pytest.approx(1.0)


def test_one_look_serves_every_label_in_the_cone():
    targets = [LabelTarget("cup", (0.9, 0.0, 0.0)), LabelTarget("book", (0.9, 0.0, 0.0))]
    session = MultiLabelSession(CONES, targets)
    result, terminals = _drive(session, {"cup": 0, "book": 0})
    moves_and_looks = [s.action for s in result.trace if not s.action.terminal]
    assert moves_and_looks == [move_to(0), look_at(0)]
    assert set(terminals) == {confirm_label("cup", 0), confirm_label("book", 0)}
    assert result.labels["cup"].detection == "cup@0" and result.labels["book"].detection == "book@0"


def test_rejection_reports_what_is_left_by_hand():
    # the cup is only ever maybe on the table; it is never seen there
    targets = [LabelTarget("cup", (0.9, 0.0, 0.0)), LabelTarget("book", (0.0, 0.0, 0.0))]
    session = MultiLabelSession(CONES, targets)
    result, _ = _drive(session, {})
    looks = sum(s.action.kind is ActionKind.PROCESS_VIEW_CONE for s in result.trace)
    assert looks >= 2 and result.labels["cup"].status is LabelStatus.REJECTED
    # 0.9 * 0.2^k / (0.9 * 0.2^k + 0.1 * 0.95^k)
    left = 0.9 * 0.2**looks / (0.9 * 0.2**looks + 0.1 * 0.95**looks)
    assert result.labels["cup"].probability == pytest.approx(left)
    assert result.labels["book"].status is LabelStatus.REJECTED
    assert result.labels["book"].probability == 0.0


def test_trace_costs_and_decision_times():
    session = MultiLabelSession(CONES, _targets(), sensing_cost=2.0)
    result, terminals = _drive(session, {"cup": 0})
    assert result.cost == pytest.approx(sum(s.cost for s in result.trace))
    assert result.trace[0].action.kind is ActionKind.MOVE
    assert result.trace[0].cost == pytest.approx(session.problem.travel_cost(-1, result.trace[0]
                                                                             .action.cone))
    assert all(s.cost == 2.0 for s in result.trace if s.action.kind is ActionKind.PROCESS_VIEW_CONE)
    assert all(s.cost == 0.0 for s in result.trace if s.action.terminal)
    assert len(result.decision_times_s) == len(result.trace)
    assert all(sum(b) == pytest.approx(1.0) for b in result.trace[-1].beliefs)


def test_step_budget_forces_every_label_closed():
    session = MultiLabelSession(CONES, _targets(DetectorModel(0.5, 0.05)), horizon=3)
    result, terminals = _drive(session, {})
    assert sum(not s.action.terminal for s in result.trace) == 3
    assert len(terminals) == 3 and all(t.kind is ActionKind.REJECT for t in terminals)


def test_budget_used_up_refuses_more_looks():
    session = MultiLabelSession(CONES, _targets(), horizon=1)
    session.update(move_to(0))
    assert session.steps_left == 0
    with pytest.raises(DtSessionError, match="step budget used up"):
        session.update(look_at(0), {"cup": True, "book": False, "stapler": False})
    assert session.next_action().terminal


def test_driving_errors_are_clear():
    session = MultiLabelSession(CONES, _targets())
    with pytest.raises(DtSessionError, match="robot is at cone -1"):
        session.update(look_at(0), {"cup": True, "book": True, "stapler": True})
    with pytest.raises(DtSessionError, match="no view cone with index 5"):
        session.update(move_to(5))
    session.update(move_to(0))
    with pytest.raises(DtSessionError, match=r"unknown label\(s\) \['mug'\]"):
        session.update(look_at(0), {"cup": True, "book": True, "stapler": True, "mug": True})
    with pytest.raises(DtSessionError, match="needs a detection result .* label 'stapler'"):
        session.update(look_at(0), {"cup": True, "book": False})
    with pytest.raises(DtSessionError, match="only a label just detected"):
        session.update(confirm_label("cup", 0))
    with pytest.raises(DtSessionError, match="observes nothing"):
        session.update(move_to(1), {"cup": True})
    session.update(look_at(0), {"cup": True, "book": False, "stapler": False})
    session.update(confirm_label("cup", 0))
    with pytest.raises(DtSessionError, match="'cup' is already decided"):
        session.update(reject_label("cup"))
    with pytest.raises(DtSessionError, match="unknown label 'mug'"):
        session.update(reject_label("mug"))
    # results for decided labels are accepted and ignored
    session.update(look_at(0), {"cup": True, "book": False, "stapler": False})
    assert session.label_results()["cup"].status is LabelStatus.CONFIRMED


def test_observations_may_be_given_per_label_as_one_object():
    session = MultiLabelSession(CONES, _targets())
    session.update(move_to(0), MultiObservation.nothing(3))
    session.update(look_at(0), MultiObservation((DETECTED, NOT_DETECTED, NOT_DETECTED)))
    assert session.belief.detected(0) and not session.belief.detected(1)


def test_bad_input_is_refused():
    with pytest.raises(DtInputError, match="no labels"):
        MultiLabelSession(CONES, [])
    with pytest.raises(DtInputError, match="duplicate label 'cup'"):
        MultiLabelSession(CONES, [LabelTarget("cup", (0.1, 0.1, 0.1)),
                                  LabelTarget("cup", (0.1, 0.1, 0.1))])
    with pytest.raises(DtInputError, match="label 'cup': view cone probabilities sum to"):
        MultiLabelSession(CONES, [LabelTarget("cup", (0.6, 0.6, 0.1))])
    with pytest.raises(DtInputError, match="unknown multi-label DT policy 'pouct'"):
        MultiLabelSession(CONES, _targets(), policy="pouct")
