"""The experience store: conjugate updates of the knowledge's rates and priors by hand, scopes,
no process-wide state, and clear errors for files that are not such a store."""

from __future__ import annotations

import sqlite3

import numpy as np
import pytest

from conceptual_map.errors import ExperienceError
from conceptual_map.knowledge import load_knowledge
from conceptual_map.knowledge.experience import (
    Evidence,
    ExperienceSession,
    ExperienceStore,
)
from conceptual_map.knowledge.learned import PRIOR_EXPOSURE, posterior_mean, posterior_rate
from conceptual_map.qsr import QsrDescription, QsrStep, load_qsr

BASE = load_knowledge()
KITCHEN = BASE.category_index("kitchen")
OFFICE = BASE.category_index("office")


@pytest.fixture()
def store(tmp_path):
    with ExperienceStore(tmp_path / "experience.sqlite") as s:
        yield s


def test_the_conjugate_update_moves_a_rate_toward_the_counts_by_hand(store) -> None:
    """A Gamma prior centred on the file's rate lambda0 and worth b0 rooms of looking:
    posterior mean (b0 lambda0 + n) / (b0 + E)."""
    assert PRIOR_EXPOSURE == 2.0
    assert BASE.object_lambda["cup"][KITCHEN] == 0.3
    store.update(None, Evidence(rooms={("cup", "kitchen"): (3.0, 2.0)}))
    learned = store.knowledge_for(BASE)
    # (2 x 0.3 + 3) / (2 + 2) = 0.9: found 3 in 2 rooms' worth, 1.5 a room observed
    assert learned.object_lambda["cup"][KITCHEN] == pytest.approx(3.6 / 4)
    assert 0.3 < learned.object_lambda["cup"][KITCHEN] < 1.5
    # more searching without finds lowers it below the file's value
    store.update(None, Evidence(rooms={("cup", "kitchen"): (0.0, 20.0)}))
    lower = store.knowledge_for(BASE).object_lambda["cup"][KITCHEN]
    assert lower == pytest.approx(3.6 / 24)
    assert lower < 0.3

    # what has no counts is the file's, and the base is not changed
    assert learned.object_lambda["cup"][OFFICE] == BASE.object_lambda["cup"][OFFICE]
    assert np.array_equal(learned.object_lambda["desk"], BASE.object_lambda["desk"])
    assert BASE.object_lambda["cup"][KITCHEN] == 0.3


def test_a_rate_the_file_calls_unlikely_is_learned_from_a_few_buildings(store) -> None:
    """The prior is worth the same looking for every rate: a label the file puts nowhere in
    a category (its default rate) is found there in a few rooms and learned, where a prior
    worth two objects found (shape 2, 200 rooms' worth at 0.01) would hardly move."""
    assert BASE.object_lambda["cup"][BASE.category_index("meeting_room")] == 0.1
    assert BASE.object_lambda["book"][KITCHEN] == BASE.default_object_lambda == 0.01
    store.update(None, Evidence(rooms={("book", "kitchen"): (4.0, 5.0)}))
    learned = store.knowledge_for(BASE).object_lambda["book"][KITCHEN]
    assert learned == pytest.approx((2 * 0.01 + 4) / (2 + 5))
    assert learned > 0.5
    assert posterior_mean(0.01, 4.0, 5.0) == pytest.approx(learned)


def test_a_support_rate_updates_the_same_way(store) -> None:
    lam0 = BASE.relation_lambda[("cerealbox", "on", "table")][KITCHEN]
    assert lam0 == 0.5
    store.update(None, Evidence(supports={("cerealbox", "on", "table", "kitchen"): (0.0, 4.0)}))
    learned = store.knowledge_for(BASE)
    assert learned.relation_lambda[("cerealbox", "on", "table")][KITCHEN] == pytest.approx(
        2 * 0.5 / (2 + 4))  # 1/6: four tables looked at, none held one
    assert posterior_rate(0.0, 2.0, 3.0, 1.0) == 0.0  # ruled out by the file stays so
    assert posterior_mean(0.0, 3.0, 1.0) == 0.0


def test_a_relation_the_file_does_not_list_is_added_once_found(store) -> None:
    key = ("book", "on", "counter")
    assert key not in BASE.relation_lambda
    store.update(None, Evidence(supports={(*key, "kitchen"): (0.0, 3.0)}))
    assert key not in store.knowledge_for(BASE).relation_lambda  # nothing found: not added
    store.update(None, Evidence(supports={(*key, "kitchen"): (2.0, 1.0)}))
    row = store.knowledge_for(BASE).relation_lambda[key]
    d = BASE.default_relation_lambda
    assert row[KITCHEN] == pytest.approx((2 * d + 2) / (2 + 4))
    assert row[OFFICE] == pytest.approx(d)  # other categories keep the file's default


def test_a_building_scope_refines_the_other_buildings_counts(store) -> None:
    """The all-buildings level takes the other buildings' counts (all less this one's); the
    building's own go on top with the file's rate_shape as a0 (1 here)."""
    assert BASE.rate_shape == 1.0
    store.update("b1", Evidence(rooms={("cup", "kitchen"): (0.0, 10.0)}))
    store.update("b2", Evidence(rooms={("cup", "kitchen"): (4.0, 2.0)}))
    everyone = store.knowledge_for(BASE).object_lambda["cup"][KITCHEN]
    assert everyone == pytest.approx((0.6 + 4) / (2 + 12))
    others = (0.6 + 4) / (2 + 2)  # b2's counts only
    b1 = store.knowledge_for(BASE, "b1").object_lambda["cup"][KITCHEN]
    assert b1 == pytest.approx((1 + 0) / (1 / others + 10))
    others = 0.6 / (2 + 10)  # b1's counts only
    b2 = store.knowledge_for(BASE, "b2").object_lambda["cup"][KITCHEN]
    assert b2 == pytest.approx((1 + 4) / (1 / others + 2))
    # each building's own looks move it from what the other buildings say: b1 searched ten
    # kitchens for nothing, b2 found four cups in two
    assert b1 < everyone and b1 < (0.6 + 4) / (2 + 2)
    assert b2 > 0.6 / (2 + 10)
    # a building the store has never seen gets the all-buildings posterior
    new = store.knowledge_for(BASE, "b3").object_lambda["cup"][KITCHEN]
    assert new == pytest.approx(everyone)


def test_room_categories_and_neighbours_are_dirichlet_counts(store) -> None:
    store.update("b1", Evidence(categories={"office": 6.0, "corridor": 2.0},
                                neighbours={("corridor", "office"): 6.0}))
    learned = store.knowledge_for(BASE)
    counts = np.zeros(len(BASE.categories))
    counts[OFFICE], counts[BASE.category_index("corridor")] = 6.0, 2.0
    assert np.allclose(learned.prior, (20.0 * BASE.prior + counts) / 28.0)
    assert learned.prior.sum() == pytest.approx(1.0)
    assert learned.prior[OFFICE] > BASE.prior[OFFICE]
    corridor = BASE.category_index("corridor")
    ratio = learned.connectivity / BASE.connectivity
    assert np.allclose(ratio, ratio.T)
    # the pair seen gains against every pair not seen, which keep one ratio
    assert ratio[KITCHEN, OFFICE] == pytest.approx(20.0 / 26.0)
    assert ratio[corridor, OFFICE] > ratio[KITCHEN, OFFICE]
    # no neighbour counts: the connectivity is the file's
    store.reset()
    assert np.array_equal(store.knowledge_for(BASE).connectivity, BASE.connectivity)


def test_the_same_store_state_gives_the_same_knowledge(tmp_path) -> None:
    """Nothing is kept in the process: two reads, and a second store object on the same
    file, give equal knowledge; a store on another file is untouched by the first."""
    path = tmp_path / "a.sqlite"
    with ExperienceStore(path) as one:
        one.update("b1", Evidence(rooms={("cup", "kitchen"): (1.0, 3.0)},
                                  categories={"kitchen": 1.0}))
        first, second = one.knowledge_for(BASE, "b1"), one.knowledge_for(BASE, "b1")
    with ExperienceStore(path) as again:
        third = again.knowledge_for(BASE, "b1")
    for k in (second, third):
        assert all(np.array_equal(first.object_lambda[lab], k.object_lambda[lab])
                   for lab in BASE.labels)
        assert np.array_equal(first.prior, k.prior)
    with ExperienceStore(tmp_path / "b.sqlite") as other:
        assert other.knowledge_for(BASE, "b1").object_lambda["cup"][KITCHEN] == 0.3


def test_reset_forgets_a_scope_or_everything(store) -> None:
    store.update("b1", Evidence(rooms={("cup", "kitchen"): (1.0, 1.0)}))
    assert store.scopes() == ["all", "building:b1"]
    assert store.reset("building:b1") > 0
    assert store.scopes() == ["all"]  # what b1 taught stays in the all-buildings counts
    assert store.export()["scopes"]["all"]["rooms"] == [
        {"label": "cup", "category": "kitchen", "found": 1.0, "exposure": 1.0}]
    store.reset()
    assert store.scopes() == [] and store.export()["scopes"] == {}


def test_update_is_one_transaction_and_refuses_a_bad_building(store) -> None:
    with pytest.raises(ExperienceError, match="building id"):
        store.update("../etc", Evidence(rooms={("cup", "kitchen"): (1.0, 1.0)}))
    assert store.scopes() == []
    with pytest.raises(ExperienceError, match="building id"):
        store.knowledge_for(BASE, "a b")


def test_files_that_are_not_a_store_are_clear_errors(tmp_path) -> None:
    with pytest.raises(ExperienceError, match="no experience store there"):
        ExperienceStore(tmp_path / "missing.sqlite", create=False)
    junk = tmp_path / "junk.sqlite"
    junk.write_text("not a database at all " * 50)
    with pytest.raises(ExperienceError, match="not an experience store"):
        ExperienceStore(junk)
    other = tmp_path / "other.sqlite"
    with sqlite3.connect(other) as db:
        db.execute("CREATE TABLE tasks (id TEXT)")
    with pytest.raises(ExperienceError, match="without its meta table"):
        ExperienceStore(other)
    newer = tmp_path / "newer.sqlite"
    ExperienceStore(newer).close()
    with sqlite3.connect(newer) as db:
        db.execute("UPDATE meta SET value = '99' WHERE key = 'schema_version'")
    with pytest.raises(ExperienceError, match="schema version 99"):
        ExperienceStore(newer)


def test_learned_qsr_counts_add_to_the_descriptions(store) -> None:
    base = load_qsr()
    known = base.descriptions_for("cup")[0]
    new = QsrDescription("cup", (QsrStep(("left", "distant"), "monitor"),), 1.0)
    assert new.key not in {d.key for d in base.descriptions}
    session = ExperienceSession(store, "b1")
    session.learn_qsr([known, new, new])
    store.update("b1", session.with_learned(Evidence()))
    learned = {d.key: d.count for d in store.qsr_for(base).descriptions}
    assert learned[known.key] == known.count + 1.0
    assert learned[new.key] == 2.0
    assert len(learned) == len(base.descriptions) + 1
