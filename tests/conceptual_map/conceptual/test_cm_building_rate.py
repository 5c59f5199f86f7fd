"""The building's rate multiplier: counts Poisson(s x lambda), s ~ Gamma(a, a) shared by rooms."""

from dataclasses import replace

import numpy as np
import pytest
import yaml
from scipy import integrate, stats

from conceptual_map.conceptual import ConceptualMap
from conceptual_map.conceptual.existence import RatePosterior
from conceptual_map.errors import KnowledgeError
from conceptual_map.knowledge import load_knowledge
from conceptual_map.knowledge.loader import DEFAULT_KNOWLEDGE_PATH, KnowledgeYamlLoader


def _by_integration(shape: float, found: int, exposure: float, mass: float) -> float:
    """P(at least one in `mass` | `found` seen where looks expected `exposure`), integrating
    the Gamma(shape, shape) prior on s against the Poisson likelihood explicitly."""
    prior = stats.gamma(shape, scale=1.0 / shape).pdf

    def weight(s: float) -> float:
        return prior(s) * stats.poisson.pmf(found, s * exposure)

    evidence = integrate.quad(weight, 0.0, np.inf)[0]
    miss = integrate.quad(lambda s: weight(s) * np.exp(-s * mass), 0.0, np.inf)[0]
    return 1.0 - miss / evidence


@pytest.mark.parametrize(("shape", "found", "exposure", "mass"),
                         [(1.0, 0, 0.0, 1.5), (1.0, 0, 3.0, 1.5), (2.5, 1, 4.0, 0.3),
                          (0.5, 0, 10.0, 2.0)])
def test_the_negative_binomial_is_the_gamma_poisson_mixture(shape, found, exposure, mass):
    posterior = RatePosterior.after(shape, found, exposure)
    expected = _by_integration(shape, found, exposure, mass)
    assert float(posterior.p_any(mass)) == pytest.approx(expected, rel=1e-6)
    assert float(posterior.mass(posterior.p_any(mass))) == pytest.approx(mass, rel=1e-9)


def _offices(knowledge, n: int) -> ConceptualMap:
    """`n` rooms believed offices (office-like appearance at every place)."""
    cmap = ConceptualMap(knowledge)
    for i in range(n):
        cmap.add_place(f"p{i}", f"office{i}")
        cmap.observe_property(f"p{i}", "appearance", "office_like")
    return cmap


def test_searching_rooms_in_vain_lowers_the_chance_in_rooms_not_searched():
    """Six offices searched for a stapler without finding one: a seventh is less likely to
    hold one than before, and more so the more was searched. With the lambdas taken as
    exact the seventh is untouched (independent counts per room)."""
    default = load_knowledge()
    assert default.rate_shape == 1.0  # the default file's least-informed prior
    for knowledge, drops in ((default, True), (replace(default, rate_shape=None), False)):
        cmap = _offices(knowledge, 7)
        values = [cmap.p_object_at("stapler", "office6")]
        for i in range(6):
            cmap.observe_search("stapler", f"office{i}", coverage=0.9, p_detect=0.9)
            values.append(cmap.p_object_at("stapler", "office6"))
        if drops:
            assert all(a > b for a, b in zip(values, values[1:], strict=False))
            assert values[-1] < 0.5 * values[0]
        else:
            assert values == pytest.approx([values[0]] * 7)


def test_a_sighting_raises_the_rate_and_looks_for_other_labels_do_not_count():
    cmap = _offices(load_knowledge(), 2)
    before = cmap.rate_posterior("stapler")
    assert before.alpha == before.beta == 1.0
    cmap.observe_search("desk", "office0", coverage=1.0, p_detect=0.9)
    assert cmap.rate_posterior("stapler") == before  # a look for desks tests no stapler rate
    cmap.observe_object("stapler", "office0")
    assert cmap.rate_posterior("stapler").mean > before.mean


def test_a_placeholders_rooms_share_the_rate():
    """Behind a placeholder one or two new rooms: their chance falls with the evidence too."""
    cmap = _offices(load_knowledge(), 4)
    cmap.add_placeholder("ph", "office0", open_space_m2=30.0, p_door=0.9)
    before = cmap.p_beyond_placeholder("stapler", "ph")
    for i in range(4):
        cmap.observe_search("stapler", f"office{i}", coverage=0.9, p_detect=0.9)
    assert 0.0 < cmap.p_beyond_placeholder("stapler", "ph") < before


def test_the_shape_is_checked_where_the_file_sets_it(tmp_path):
    data = yaml.load(DEFAULT_KNOWLEDGE_PATH.read_text(), Loader=KnowledgeYamlLoader)
    del data["objects"]["rate_shape"]
    path = tmp_path / "exact.yaml"
    path.write_text(yaml.safe_dump(data))
    assert load_knowledge(path).rate_shape is None  # left out: the lambdas are exact
    data["objects"]["rate_shape"] = -1
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(KnowledgeError, match="objects.rate_shape"):
        load_knowledge(path)


def test_the_exposure_is_what_the_looks_for_the_label_thinned():
    """A room search for markers thins the room's own count and, while nothing has looked
    for desks there, the markers on desks not found yet; once desks have been looked for,
    their unseen markers are thinned by those looks (`unexplained_lambda`), so the marker
    search no longer exposes them."""
    knowledge = load_knowledge()
    office = knowledge.category_index("office")
    for looked_for_desks in (False, True):
        cmap = _offices(knowledge, 1)
        if looked_for_desks:
            cmap.observe_search("desk", "office0", coverage=0.5, p_detect=0.9)
        cmap.observe_search("whiteboardmarker", "office0", coverage=1.0, p_detect=0.8)
        exposed = cmap.objects.searched_lambda("whiteboardmarker", "office0")[office]
        unexposed = cmap.objects.unexplained_lambda("whiteboardmarker", "office0")[office]
        total = cmap.objects.fresh_room_lambda("whiteboardmarker")[office]
        if looked_for_desks:
            on_desks = (knowledge.room_lambda("desk")[office]
                        * knowledge.relation_lambda_of("whiteboardmarker", "on", "desk")[office])
            assert exposed == pytest.approx(0.8 * (total - on_desks))
        else:
            assert exposed + unexposed == pytest.approx(total)
