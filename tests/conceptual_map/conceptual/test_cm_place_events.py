"""Place-map events drive the conceptual map: rooms, links through doors, merges, placeholders."""

import pytest

from conceptual_map.conceptual import ConceptualError, ConceptualMap
from conceptual_map.conceptual.place_events import GeometryEvidence, PlaceMapFeed
from conceptual_map.places.model import Change, EntityKind, MapEvent, Place, Placeholder, Room


def _room(rid, places, doors, area=12.0, elongation=1.5, change=Change.APPEARED):
    room = Room(rid, frozenset(places), frozenset(doors), area, elongation)
    return MapEvent(EntityKind.ROOM, change, rid, room)


def _placeholder(pid, place, open_space=8.0, near_door=None, change=Change.APPEARED):
    ph = Placeholder(pid, (0.0, 0.0), (1.0, 0.0), 1.0, open_space, place, near_door)
    return MapEvent(EntityKind.PLACEHOLDER, change, pid, ph)


def _fed() -> tuple[ConceptualMap, PlaceMapFeed]:
    cmap = ConceptualMap()
    feed = PlaceMapFeed(cmap)
    feed.apply([
        _room("room1", {"p1", "p2"}, {"door1"}, area=25.0, elongation=5.0),
        _room("room2", {"p3"}, {"door1", "door2"}, area=9.0, elongation=1.1),
        _placeholder("ph1", "p3"),
    ])
    return cmap, feed


def test_rooms_places_links_and_placeholders_arrive():
    cmap, _ = _fed()
    assert cmap.graph.places_of("room1") == {"p1", "p2"}
    assert cmap.graph.neighbours("room1") == {"room2"}
    assert cmap.placeholders["ph1"].room == "room2"
    assert cmap.placeholders["ph1"].open_space_m2 == 8.0
    belief = cmap.room_category("room1")
    assert max(belief, key=belief.get) == "corridor"


def test_geometry_bins():
    geometry = GeometryEvidence()
    assert [geometry.size(a) for a in (3.0, 10.0, 30.0)] == ["small", "medium", "large"]
    assert [geometry.shape(e) for e in (1.0, 1.6, 3.0)] == ["square", "rectangular", "elongated"]


def test_a_new_shared_door_links_rooms_and_a_lost_one_unlinks_them():
    cmap, feed = _fed()
    feed.apply([_room("room3", {"p4"}, {"door2"})])
    assert cmap.graph.neighbours("room2") == {"room1", "room3"}
    feed.apply([_room("room3", {"p4"}, set(), change=Change.CHANGED)])
    assert cmap.graph.neighbours("room3") == frozenset()


def test_a_vanished_room_is_merged_into_the_room_that_took_its_places():
    cmap, feed = _fed()
    cup = cmap.observe_object("cup", "room2")
    feed.apply([
        _room("room1", {"p1", "p2", "p3"}, {"door2"}, change=Change.CHANGED),
        _room("room2", {"p3"}, {"door1", "door2"}, change=Change.VANISHED),
    ])
    assert not cmap.graph.has_room("room2")
    assert cmap.objects.objects[cup].room == "room1"
    assert cmap.placeholders["ph1"].room == "room1"
    assert cmap.p_object_at("cup", "room1") == 1.0


def test_placeholder_changes_and_vanishing():
    cmap, feed = _fed()
    feed.apply([_placeholder("ph1", "p1", open_space=20.0, near_door="door1",
                             change=Change.CHANGED)])
    evidence = cmap.placeholders["ph1"]
    assert (evidence.room, evidence.open_space_m2, evidence.p_door) == ("room1", 20.0, 0.9)
    feed.apply([_placeholder("ph1", "p1", change=Change.VANISHED)])
    assert "ph1" not in cmap.placeholders


def test_a_placeholder_waits_until_its_place_has_a_room():
    cmap, feed = _fed()
    feed.apply([_placeholder("ph2", "p9")])
    assert "ph2" not in cmap.placeholders
    feed.apply([_room("room4", {"p9"}, set())])
    assert cmap.placeholders["ph2"].room == "room4"


def test_vanished_places_and_empty_rooms_are_removed():
    cmap, feed = _fed()
    place = Place("p2", (0.0, 0.0), 0.0)
    feed.apply([MapEvent(EntityKind.PLACE, Change.VANISHED, "p2", place)])
    assert cmap.graph.places_of("room1") == {"p1"}
    feed.apply([_room("room2", {"p3"}, set(), change=Change.VANISHED)])
    assert not cmap.graph.has_room("room2")
    assert "ph1" not in cmap.placeholders


def test_removing_a_room_with_objects_is_refused():
    cmap, _ = _fed()
    cmap.observe_object("cup", "room2")
    with pytest.raises(ConceptualError, match="holds objects"):
        cmap.remove_room("room2")


def test_links_inherited_by_a_merge_follow_the_doors_of_the_surviving_room():
    cmap, feed = _fed()
    feed.apply([_room("room3", {"p4"}, {"door2"})])
    feed.apply([
        _room("room1", {"p1", "p2", "p3"}, {"door1"}, change=Change.CHANGED),
        _room("room2", {"p3"}, {"door1", "door2"}, change=Change.VANISHED),
    ])
    assert cmap.graph.neighbours("room1") == frozenset()
