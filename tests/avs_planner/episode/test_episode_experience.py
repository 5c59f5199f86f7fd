"""What a finished episode teaches the experience store, read from a mind built by hand (no
simulator): counts per believed room category, looks as exposure, door links."""

from __future__ import annotations

import pytest

from avs_planner.episode.experience import CONFIDENT, episode_evidence, room_categories
from avs_planner.episode.mind import Mind


def _mind() -> Mind:
    """r1 a kitchen, r2 an office (both believed >= 0.8), r3 unsure; r1-r2 and r2-r3 joined."""
    mind = Mind()
    cmap = mind.cmap
    for room, looks in (("r1", "kitchen_like"), ("r2", "office_like")):
        for i in range(6):
            cmap.add_place(f"{room}p{i}", room)
            cmap.observe_property(f"{room}p{i}", "appearance", looks)
    cmap.add_place("r3p0", "r3")
    cmap.observe_property("r3p0", "appearance", {"kitchen_like": 0.5, "office_like": 0.5})
    cmap.connect_rooms("r1", "r2")
    cmap.connect_rooms("r2", "r3")
    return mind


def test_rooms_count_under_their_category_only_when_believed_confidently() -> None:
    mind = _mind()
    assert CONFIDENT == 0.8
    cats = room_categories(mind)
    assert cats == {"r1": "kitchen", "r2": "office"}
    assert max(mind.cmap.room_marginal("r3")) < 0.8


def test_episode_evidence_counts_finds_and_looks_by_hand() -> None:
    mind = _mind()
    # a room search for cups in the kitchen: half of it, detector 0.8 -> 0.4 of a room
    mind.searched("cup", "in", "r1", 0.5, 0.8)
    # a table there, its top searched (all of it, detector 0.5) and a cup found on it
    table = mind.add_object("table", (1.0, 1.0, 0.4), room="r1")
    mind.searched("cup", "on", table.id, 1.0, 0.5)
    mind.add_object("cup", (1.0, 1.0, 0.8), support=table.id)
    # the office searched in vain twice (0.9 x 0.5 each): 1 - 0.55^2 of a room
    mind.searched("cup", "in", "r2", 0.9, 0.5)
    mind.searched("cup", "in", "r2", 0.9, 0.5)
    # the unsure room: searched and a cup found, but it teaches nothing
    mind.searched("cup", "in", "r3", 1.0, 0.8)
    mind.add_object("cup", (9.0, 9.0, 0.0), room="r3")
    evidence = episode_evidence(mind)
    assert evidence.rooms[("cup", "kitchen")] == pytest.approx((0.0, 0.4))
    assert evidence.rooms[("cup", "office")] == pytest.approx((0.0, 1.0 - 0.55 ** 2))
    assert evidence.supports == {("cup", "on", "table", "kitchen"): pytest.approx((1.0, 0.5))}
    # the table was never looked for: it teaches no table rate
    assert not any(key[0] == "table" for key in evidence.rooms)
    assert evidence.categories == {"kitchen": 1, "office": 1}
    assert evidence.neighbours == {("kitchen", "office"): 1}  # r2-r3: r3 unsure
    assert evidence.qsr == {}


def test_a_mind_that_looked_at_nothing_teaches_only_its_rooms() -> None:
    evidence = episode_evidence(_mind())
    assert evidence.rooms == {} and evidence.supports == {}
    assert evidence.categories == {"kitchen": 1, "office": 1}
