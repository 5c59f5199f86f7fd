"""Object existence: Poisson probabilities, hierarchical sums, Bayes after failed searches.

With the lambdas taken as exact (`rate_shape` None); the uncertain building rate is tested in
test_cm_building_rate.py."""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.stats import poisson

from conceptual_map.conceptual import (
    ConceptualError,
    ConceptualMap,
    RelatedSpace,
    p_at_least,
    p_at_least_one,
)
from conceptual_map.knowledge import load_knowledge

EXACT = replace(load_knowledge(), rate_shape=None)


def _posterior_by_enumeration(prior: np.ndarray, lam: np.ndarray, detect: list[float]) -> float:
    """P(n >= 1 | every search missed), summing over category and count explicitly."""
    miss = np.prod([1.0 - q for q in detect])
    counts = np.arange(0, 80)
    joint = prior[:, None] * poisson.pmf(counts[None, :], lam[:, None]) * miss ** counts[None, :]
    return float(joint[:, 1:].sum() / joint.sum())


def test_p_at_least_one_is_one_minus_exp_minus_lambda():
    assert p_at_least_one(0.0) == 0.0
    assert p_at_least_one(2.0) == pytest.approx(1 - math.exp(-2.0))


def test_p_at_least_is_scipy_s_poisson_survival_function_to_the_last_bit():
    """Computed without scipy.stats (slow to import), as scipy.stats computes it; edge cases
    included (k <= 0, lambda 0, inf, NaN, negative)."""
    rng = np.random.default_rng(3)
    lams = [np.array([0.0, 1e-300, 1e-9, 0.4, 2.0, 60.0, 1e4, np.inf, np.nan, -1.0]),
            rng.random((4, 5)) * 10.0 ** rng.integers(-6, 3, (4, 5)), 0.0, 2.5, -1.0]
    for k in range(-1, 9):
        for lam in lams:
            with np.errstate(all="ignore"):
                expected = np.asarray(poisson.sf(k - 1, np.asarray(lam, dtype=float)),
                                      dtype=float)
            got = p_at_least(k, lam)
            assert got.shape == expected.shape
            assert np.array_equal(got, expected, equal_nan=True), (k, lam)


@pytest.mark.parametrize("searches", [[(0.5, 0.8)], [(0.9, 0.8)], [(0.5, 0.8), (0.7, 0.9)]])
def test_failed_search_posterior_is_bayes_rule(searches):
    cmap = ConceptualMap(EXACT)
    cmap.add_room("kitchen1")
    prior_p = cmap.p_object_at("table", "kitchen1", include_sublocations=False)
    for coverage, p_detect in searches:
        cmap.observe_search("table", "kitchen1", coverage, p_detect)
    knowledge = cmap.knowledge
    expected = _posterior_by_enumeration(
        knowledge.prior, knowledge.room_lambda("table"), [c * d for c, d in searches]
    )
    posterior = cmap.p_object_at("table", "kitchen1", include_sublocations=False)
    assert posterior == pytest.approx(expected, abs=1e-9)
    assert posterior < prior_p


def test_failed_search_is_also_evidence_about_the_room_category():
    cmap = ConceptualMap(EXACT)
    cmap.add_room("r")
    before = cmap.room_category("r")["kitchen"]
    cmap.observe_search("counter", "r", coverage=1.0, p_detect=0.9)
    assert cmap.room_category("r")["kitchen"] < before


def test_repeated_searches_of_a_table_keep_lowering_the_probability():
    cmap = ConceptualMap(EXACT)
    cmap.add_place("p", "k")
    cmap.observe_property("p", "appearance", "kitchen_like")
    table = cmap.observe_object("table", "k")
    values = [cmap.p_object_at("cerealbox", ("on", table))]
    for _ in range(4):
        cmap.observe_search("cerealbox", RelatedSpace("on", table), 0.8, 0.8)
        values.append(cmap.p_object_at("cerealbox", ("on", table)))
    assert all(a > b for a, b in zip(values, values[1:], strict=False))
    assert values[-1] < 0.05


def test_room_probability_adds_lambdas_of_its_related_spaces():
    cmap = ConceptualMap(EXACT)
    cmap.add_room("r")
    table = cmap.observe_object("table", "r")
    shelf = cmap.observe_object("shelf", "r")
    cmap.observe_object("cup", "r", on=table)  # no cereal-box entry for cups: not summed
    knowledge = cmap.knowledge
    lam = (knowledge.room_lambda("cerealbox")
           + knowledge.relation_lambda_of("cerealbox", "on", "table")
           + knowledge.relation_lambda_of("cerealbox", "in", "shelf"))
    expected = float(cmap.room_marginal("r") @ (1 - np.exp(-lam)))
    assert cmap.p_object_at("cerealbox", "r") == pytest.approx(expected)
    direct = cmap.p_object_at("cerealbox", "r", include_sublocations=False)
    on_table = cmap.p_object_at("cerealbox", ("on", table))
    in_shelf = cmap.p_object_at("cerealbox", ("in", shelf))
    assert cmap.p_object_at("cerealbox", "r") > max(direct, on_table, in_shelf)


def test_a_detected_object_makes_its_location_certain():
    cmap = ConceptualMap(EXACT)
    cmap.add_room("r")
    table = cmap.observe_object("table", "r")
    cmap.observe_object("cup", "r", on=table)
    assert cmap.p_object_at("cup", ("on", table)) == 1.0
    assert cmap.p_object_at("cup", "r") == 1.0
    assert cmap.p_object_at("cup", "r", include_sublocations=False) < 1.0


def test_abstract_location_probabilities_come_from_default_knowledge():
    cmap = ConceptualMap(EXACT)
    knowledge = load_knowledge()
    kitchen = knowledge.category_index("kitchen")
    assert cmap.p_object_at_category("table", "kitchen") == pytest.approx(
        1 - math.exp(-knowledge.room_lambda("table")[kitchen]))
    assert cmap.p_object_at_category("cerealbox", "kitchen", "table") == pytest.approx(
        1 - math.exp(-0.5))
    assert cmap.p_object_at_category("cerealbox", "kitchen", "table") > \
        cmap.p_object_at_category("cerealbox", "office", "table")


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (lambda m: m.observe_object("unicorn", "r"), "unknown object label 'unicorn'"),
        (lambda m: m.observe_object("cup", "attic"), "unknown room 'attic'"),
        (lambda m: m.observe_object("cup", "r", on="object9"), "unknown support object"),
        (lambda m: m.observe_search("cup", "r", 1.5, 0.8), "coverage must be in"),
        (lambda m: m.observe_search("cup", "r", "all", 0.8), "coverage must be a number"),
        (lambda m: m.observe_search("cup", ("under", "object1"), 0.5, 0.8), "relation"),
        (lambda m: m.p_object_at("cup", ("on", "object9")), "unknown object 'object9'"),
        (lambda m: m.p_object_at("cup", 3), "location must be"),
        (lambda m: m.p_object_at_category("cup", "garage"), "unknown room category"),
        (lambda m: m.p_object_at_category("cup", "kitchen", "moon"), "unknown object label"),
        (lambda m: m.observe_object("cup", "r", object_id="object1"), "already used"),
    ],
)
def test_bad_object_input_raises_clear_errors(action, message):
    cmap = ConceptualMap(EXACT)
    cmap.add_room("r")
    cmap.observe_object("table", "r")
    with pytest.raises(ConceptualError, match=message):
        action(cmap)


def test_a_forgotten_object_leaves_the_beliefs_as_if_never_seen():
    """A detection that proved false is taken back: room category beliefs return to what
    they were before it, and a support still holding an object cannot be forgotten."""
    cmap = ConceptualMap(EXACT)
    cmap.add_room("room1")
    before = cmap.room_category("room1")
    oid = cmap.observe_object("cerealbox", "room1")
    assert cmap.room_category("room1") != pytest.approx(before)
    cmap.forget_object(oid)
    assert oid not in cmap.objects.objects
    assert cmap.room_category("room1") == pytest.approx(before)
    table = cmap.observe_object("table", "room1")
    cmap.observe_object("cerealbox", "room1", on=table)
    with pytest.raises(ConceptualError, match="still holds"):
        cmap.forget_object(table)
    with pytest.raises(ConceptualError, match="unknown object"):
        cmap.forget_object("object99")


def test_the_room_hypothesis_counts_supports_not_found_yet_not_the_prior_number():
    """P(label in the room, off its known supports): the room's own lambda and the supports
    still unfound (their prior count thinned by the looks for them) times the per-support
    lambda. A room whose desks were all looked for, and found, no longer holds the prior
    number of desks' worth of keyboards (which kept a searched office worth another room
    search: the known desks' keyboards are in their own `on` spaces)."""
    cmap = ConceptualMap(EXACT)
    cmap.add_room("office1")
    knowledge = cmap.knowledge
    prior = cmap.p_object_in_room_per_category("keyboard", "office1")
    np.testing.assert_allclose(prior, p_at_least_one(knowledge.total_room_lambda("keyboard")))
    cmap.observe_object("desk", "office1")
    cmap.observe_glimpses("desk", "office1", 0.9)  # 90% of the room's desks would be seen
    after = cmap.p_object_in_room_per_category("keyboard", "office1")
    expected = knowledge.room_lambda("keyboard") + knowledge.room_lambda("desk") * 0.1 * \
        knowledge.relation_lambda_of("keyboard", "on", "desk")
    np.testing.assert_allclose(after, p_at_least_one(expected))
    office = knowledge.category_index("office")
    assert after[office] < 0.5 * prior[office]
    # the keyboard's own looks thin the room's own lambda; unlooked-for supports keep theirs
    cmap.observe_glimpses("keyboard", "office1", 0.5)
    thinned = cmap.p_object_in_room_per_category("keyboard", "office1")
    np.testing.assert_allclose(thinned, p_at_least_one(
        expected - 0.5 * knowledge.room_lambda("keyboard")))


def test_a_search_that_ends_after_its_room_was_merged_counts_for_the_room_that_took_it():
    """The map may merge the room a DT search began in before the search ends (a door
    hypothesis dropped): its evidence goes to the merged room, not to an unknown room."""
    cmap = ConceptualMap(EXACT)
    cmap.add_room("room1")
    cmap.add_room("room10")
    cmap.merge_rooms("room1", "room10")
    before = cmap.p_object_at("cerealbox", "room1")
    cmap.observe_search("cerealbox", "room10", coverage=0.9, p_detect=0.9)
    assert cmap.current_room("room10") == "room1"
    assert cmap.p_object_at("cerealbox", "room1") < before
    cmap.add_room("room2")
    cmap.remove_room("room2")
    assert cmap.current_room("room2") is None
    with pytest.raises(ConceptualError, match="unknown room 'room2'"):
        cmap.observe_search("cerealbox", "room2", coverage=0.9, p_detect=0.9)
