"""The learned priors' arithmetic: posterior means of the knowledge's rates, room-category
prior and connectivity given counts from the experience store (`experience.py`, which keeps
the counts; the module doc there says what is counted).

**Rates.** A label's count in a room (or on one support) of a category is Poisson with rate
lambda per unit of exposure (one room, or one support instance, looked through completely
with a perfect detector). At the all-buildings level the prior on lambda is a Gamma centred on
the file's rate lambda0 and worth `PRIOR_EXPOSURE` units of exposure (Gamma(b0 lambda0, b0),
b0 = `PRIOR_EXPOSURE`): after n objects found in exposure E the posterior mean is
(b0 lambda0 + n) / (b0 + E) (`posterior_mean`). The prior is worth the same *looking* for
every rate, not the same number of objects found: the file's small default rates (0.005 on a
support, 0.01 in a room, for what it does not list) say "nothing known", and a Gamma of
shape a0 = 2 centred there (the first version: worth two objects found, b0 = a0 / lambda0 =
400 supports looked at) let no plausible amount of searching move them, so a building kind
whose cups live in meeting rooms was never learned. One building's rate is the same update
again with the all-buildings posterior mean as its prior mean and the knowledge's
`rate_shape` a as the Gamma's shape (`posterior_rate`): that is the model's own prior on one
building's rate (s lambda with s ~ Gamma(a, a), `conceptual/existence.py`).

**Relations the file does not list** (a book on a kitchen counter) are added once some
building found one: their prior mean is the file's `default_relation_lambda`, and the
planner then counts that support's space for the label (`ObjectLedger.sublocations`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
from types import MappingProxyType

import numpy as np

from conceptual_map.knowledge.model import Knowledge

PRIOR_EXPOSURE = 2.0
"""b0: the file's rate counts as much as two rooms (or support instances) looked through
completely. The file's rates are plausible guesses, not measurements: two rooms' worth lets a
handful of searched rooms move a rate, while one room found holding three cups does not
make it three."""

CATEGORY_STRENGTH = 20.0
"""Dirichlet concentration of the file's room-category prior in the all-buildings scope: worth
twenty rooms seen (a few buildings' worth), so one building's mix does not become everyone's."""

BUILDING_CATEGORY_STRENGTH = 5.0
"""The same for one building on top of the all-buildings posterior: its own rooms soon
dominate (an office floor is mostly offices)."""

NEIGHBOUR_STRENGTH = 20.0
"""Dirichlet concentration of the pair distribution the file's connectivity implies: worth
twenty door links seen."""

Counts = dict[tuple[str, ...], tuple[float, float]]
"""A key -> (found, exposure)."""


Update = Callable[[float, float, float], float]
"""(prior mean, found, exposure) -> posterior mean."""


def posterior_mean(prior_mean: float, found: float, exposure: float,
                   prior_exposure: float = PRIOR_EXPOSURE) -> float:
    """Posterior mean of a Poisson rate whose Gamma prior has mean `prior_mean` and is worth
    `prior_exposure` units: (b0 lambda0 + n) / (b0 + E). A zero prior mean stays 0 (the
    knowledge rules the label out there)."""
    if prior_mean <= 0.0:
        return 0.0
    return (prior_exposure * prior_mean + found) / (prior_exposure + max(0.0, exposure))


def posterior_rate(prior_mean: float, strength: float, found: float, exposure: float) -> float:
    """Posterior mean of a Poisson rate with a Gamma(a0, a0 / prior_mean) prior after `found`
    objects in `exposure` units: (a0 + n) / (a0 / prior_mean + E). A zero prior mean stays 0
    (the knowledge rules the label out there)."""
    if prior_mean <= 0.0:
        return 0.0
    return (strength + found) / (strength / prior_mean + max(0.0, exposure))


def rate_of(knowledge: Knowledge, key: tuple[str, ...]) -> float | None:
    category = key[-1]
    if category not in knowledge.categories:
        return None
    k = knowledge.category_index(category)
    if len(key) == 2:
        row = knowledge.object_lambda.get(key[0])
    else:
        row = knowledge.relation_lambda.get((key[0], key[1], key[2]))
    return None if row is None else float(row[k])


def posterior_knowledge(base: Knowledge, rooms: Counts, supports: Counts,
               categories: Mapping[str, float], neighbours: Mapping[tuple[str, str], float],
               update: Update, category_strength: float) -> Knowledge:
    """One level of the update: `base`'s values are the prior means, `update` the rates'
    posterior mean (module doc). Counts for labels or categories `base` does not list are
    left out; a relation it does not list is added where something was found."""
    index = {c: i for i, c in enumerate(base.categories)}
    objects = {label: row.copy() for label, row in base.object_lambda.items()}
    for (label, category), (n, e) in rooms.items():
        if label in objects and category in index:
            k = index[category]
            objects[label][k] = update(float(objects[label][k]), n, e)
    relations = {key: row.copy() for key, row in base.relation_lambda.items()}
    found = {key[:3] for key, (n, _) in supports.items() if n > 0}
    for key in sorted(found - set(relations)):
        if key[0] in objects and key[2] in objects:
            relations[key] = np.full(len(index), float(base.default_relation_lambda))
    for (label, relation, support, category), (n, e) in supports.items():
        key = (label, relation, support)
        if key in relations and category in index:
            k = index[category]
            relations[key][k] = update(float(relations[key][k]), n, e)
    counts = np.zeros(len(index))
    for category, n in categories.items():
        if category in index:
            counts[index[category]] += n
    prior = (category_strength * base.prior + counts) / (category_strength + counts.sum())
    return replace(base, object_lambda=MappingProxyType(objects),
                   relation_lambda=MappingProxyType(relations), prior=prior,
                   connectivity=_connectivity(base, neighbours, index), _category_index={})


def _connectivity(base: Knowledge, neighbours: Mapping[tuple[str, str], float],
                  index: Mapping[str, int]) -> np.ndarray:
    """phi scaled by P(pair) / P0(pair) (module doc)."""
    phi = base.connectivity.copy()
    n = np.zeros_like(phi)
    for (a, b), count in neighbours.items():
        if a in index and b in index:
            i, j = index[a], index[b]
            n[i, j] += count
            if i != j:
                n[j, i] += count
    total = float(np.triu(n).sum())
    if total <= 0.0:
        return phi
    pair = np.outer(base.prior, base.prior) * phi
    upper = np.triu(pair) + np.triu(pair, 1)  # unordered pairs: a != b drawn either way
    p0 = upper / upper.sum()
    p0 = np.maximum(p0, p0.T)  # the same value on both sides of the diagonal
    alpha = NEIGHBOUR_STRENGTH
    ratio = (alpha + np.divide(n, p0, out=np.zeros_like(n), where=p0 > 0)) / (alpha + total)
    return phi * ratio
