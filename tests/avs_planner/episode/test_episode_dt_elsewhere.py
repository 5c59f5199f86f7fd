"""A view-cone look that sees the target beside the location it searches: confirmed as the
watch confirms what it sees, the target becomes a known object and the search stops
(`ViewConeSearch._confirmed_elsewhere`); before, such a detection was dropped."""

from __future__ import annotations

from types import SimpleNamespace

from avs_planner.episode.dt_search import ViewConeSearch


def _seen(label: str, x: float, sid: int = 1) -> SimpleNamespace:
    return SimpleNamespace(id=sid, label=label, position=(x, 1.0, 0.8), confidence=0.9)


def _search(frames: list[list[SimpleNamespace]], confirm: bool, known_x: float | None = None,
            label: str = "book"):
    """A search of `label` on object1 (inside: x < 2) whose context returns `frames` in turn."""
    emitted: list[tuple[str, dict]] = []
    placed: list[SimpleNamespace] = []
    sensing = SimpleNamespace(
        unplaced=[], glimpses=None,
        known_near=lambda s: known_x is not None and abs(s.position[0] - known_x) < 0.5,
        confirm=lambda seen: confirm)

    def place_seen():
        placed.extend(sensing.unplaced)
        sensing.unplaced.clear()
        return SimpleNamespace(id="object9") if placed else None

    sensing.place_seen = place_seen
    context = SimpleNamespace(
        detect=lambda labels: frames.pop(0), stats=SimpleNamespace(detections=[]),
        builder=SimpleNamespace(task=SimpleNamespace(target="book")),
        emit=lambda kind, **fields: emitted.append((kind, fields)))
    search = ViewConeSearch(context, None, sensing, None, {}, label, "on", "object1")
    search._inside = lambda seen, relation, location: seen.position[0] < 2.0
    return search, emitted, placed


def test_the_target_seen_beside_the_searched_support_is_confirmed_and_known() -> None:
    far = _seen("book", 4.0)
    search, emitted, placed = _search([[_seen("shelf", 0.5, 2), far]], confirm=True)
    assert search._detect_once("book", "on", "object1") is None  # not on object1
    assert search.elsewhere is far
    assert search._confirmed_elsewhere()
    assert placed == [far] and search.elsewhere is None
    assert emitted == [("observation", {"label": "book", "detected": True, "elsewhere": True,
                                        "position": [4.0, 1.0, 0.8]})]
    assert not search._confirmed_elsewhere()  # nothing left to confirm


def test_a_detection_elsewhere_that_does_not_hold_is_dropped() -> None:
    search, emitted, placed = _search([[_seen("book", 4.0)]], confirm=False)
    assert search._detect_once("book", "on", "object1") is None
    assert not search._confirmed_elsewhere()
    assert placed == [] and emitted[0][1]["detected"] is False


def test_known_objects_matches_and_other_searches_are_not_elsewhere() -> None:
    # one the robot knows already (a book reported before, a counted instance)
    search, _, _ = _search([[_seen("book", 4.0)]], confirm=True, known_x=4.0)
    assert search._detect_once("book", "on", "object1") is None and search.elsewhere is None
    # a match on the support itself is the DT's, not elsewhere
    inside = _seen("book", 1.0)
    search, _, _ = _search([[inside, _seen("book", 4.0, 2)]], confirm=True)
    assert search._detect_once("book", "on", "object1") is inside and search.elsewhere is None
    # a search for a support (a desk to search the target on): the watch's business
    search, _, _ = _search([[_seen("desk", 4.0)]], confirm=True, label="desk")
    assert search._detect_once("desk", "on", "object1") is None and search.elsewhere is None
