"""The state builder: AVS problems from the robot's maps that the linter accepts and the CP
solves with the active visual search paper's kind of first plan (assume a kitchen behind a
placeholder, search it)."""

from __future__ import annotations

import pytest

from avs_planner.cp.continual import ContinualPlanner
from avs_planner.cp.search import SearchOptions
from avs_planner.episode import EpisodeError
from avs_planner.episode.domain import domain_text
from avs_planner.episode.state_builder import SearchTask, StateBuilder
from avs_planner.pddl import PddlSource, Severity, check, read_text

OPTIONS = SearchOptions(weight=3.0, heuristic="hadd", timeout_s=30.0)


def test_problem_text_passes_the_linter(corridor_mind) -> None:
    _, builder, _ = corridor_mind
    text = builder.build().to_pddl()
    found = check(PddlSource("domain.pddl", domain_text()), [PddlSource("episode.pddl", text)])
    assert [d for d in found if d.severity is Severity.ERROR] == []


def test_built_problem_has_places_placeholders_rooms_and_virtual_objects(corridor_mind) -> None:
    mind, builder, _ = corridor_mind
    state = builder.build()
    assert state.objects["placeholder"], "a first look around the corridor leaves frontiers"
    assert ("at", mind.place_map.current_place) in state.atoms
    assert "new-room1" in state.objects["room"] and "new-object1" in state.objects["visualobject"]
    assert ("virtual", "new-room1") in state.atoms
    assert state.objects["label"][0] == "cerealbox" and "table" in state.objects["label"]
    moves = [v for (name, *_), v in state.values.items() if name == "move-cost" and v > 0]
    assert moves and all(0.1 < v < 20 for v in moves)  # metres along the place graph
    for ph in state.objects["placeholder"]:
        assert ("connected", state.robot_place, ph) in state.atoms


def test_cp_plans_the_built_problem_with_assumptions(corridor_mind) -> None:
    _, builder, _ = corridor_mind
    state = builder.build()
    planner = ContinualPlanner(state.problem(), OPTIONS)
    result = planner.replan(state.world_state())
    assert result.solved
    names = [s.name for s in result.plan]
    assert names[0].startswith("assume-")
    assert "move" in names and names[-1] == "reportposition"
    assert any(n.startswith("searchforobject") for n in names)
    assert 0.0 < result.probability < 1.0


def test_text_and_direct_problems_give_the_same_plan(corridor_mind) -> None:
    _, builder, _ = corridor_mind
    state = builder.build()
    direct = ContinualPlanner(state.problem(), OPTIONS).replan(state.world_state())
    parsed = ContinualPlanner(read_text(domain_text(), state.to_pddl()), OPTIONS).replan()
    assert [s.label for s in direct.plan] == [s.label for s in parsed.plan]
    assert direct.probability == pytest.approx(parsed.probability, rel=1e-5)


def test_category_restriction_zeroes_other_categories(corridor_mind) -> None:
    mind, _, _ = corridor_mind
    state = StateBuilder(mind, SearchTask("cerealbox", "living_room")).build()
    values = {k: v for k, v in state.values.items() if k[0] == "p-obj-in"}
    assert all(v == 0.0 for k, v in values.items() if k[3] != "living_room")
    assert any(v > 0.0 for k, v in values.items() if k[3] == "living_room")


def test_unknown_label_or_category_is_a_clear_error(corridor_mind) -> None:
    mind, _, _ = corridor_mind
    with pytest.raises(EpisodeError, match="unknown target label 'unicorn'"):
        StateBuilder(mind, SearchTask("unicorn"))
    with pytest.raises(EpisodeError, match="unknown room category 'dungeon'"):
        StateBuilder(mind, SearchTask("cerealbox", "dungeon"))
