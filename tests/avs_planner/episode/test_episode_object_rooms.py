"""Known objects follow the map's rooms: one credited to the room the robot looked from moves
to its own room once the map parts that space off (`Mind._place_objects`)."""

from __future__ import annotations


def test_a_table_seen_through_a_door_moves_to_its_room_once_the_robot_maps_it(corridor) -> None:  # noqa: ANN001
    mind, _, executor = corridor
    corridor_room = mind.place_map.room_of(mind.place_map.current_place)
    # the office's table behind the door north of the corridor, credited to the corridor as
    # a sighting from the corridor was before the room beyond existed
    table = mind.add_object("table", (8.95, 5.37, 0.38), room=corridor_room)
    assert mind.objects[table.id].room == corridor_room
    executor.drive_to((8.0, 5.0))
    room = mind.objects[table.id].room
    assert room != corridor_room
    assert room == mind.place_map.room_of(mind.place_map.current_place)
    assert mind.cmap.objects.objects[table.id].room == room
    assert mind.cmap.p_object_at("table", room) == 1.0
