"""The probability fluents of an AVS problem, read from the robot's conceptual map.

The state builder (`state_builder.py`) decides which objects and atoms a problem has; this
module fills in the numbers the CP weighs its plans by: `p-room-category` and
`p-placeholder-category` (the category beliefs), `p-obj-in` and `p-obj-on` (where the target
and its supports may be, per category, after every look so far) and `p-find-on` (a search of
a known support, thinned by that support's own looks), and the judgements made from the same
evidence: a support settled as not holding the target, a room that can no longer hold it.

Kept apart because these are questions about evidence, asked of the conceptual map, while the
builder's are about the problem's structure (which places, rooms and objects enter, how they
connect); either can change without the other. A number below `min_probability` becomes 0
(the planner drops such actions), and with a task's room category every other category's 0.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from avs_planner.cp.task import Atom
from avs_planner.episode.mind import Mind
from avs_planner.episode.viewcones import p_at_support, support_spaces

if TYPE_CHECKING:
    from avs_planner.episode.state_builder import BuilderConfig, SearchTask


class Probabilities:
    """One task's probability fluents over the mind's current beliefs (see the module's doc).
    Cheap to make: the state builder makes one per use, so its current settings count."""

    def __init__(self, mind: Mind, task: SearchTask, config: BuilderConfig) -> None:
        self.mind, self.task, self.config = mind, task, config

    def categories(self, rooms: list[str], virtual: list[str], placeholders: set[str],
                   categories: list[str], values: dict[Atom, float]) -> None:
        """`p-room-category` of the known rooms (their belief) and of the virtual ones (0:
        a plan assumes theirs), and `p-placeholder-category` (what lies beyond each)."""
        cmap = self.mind.cmap
        for rid in rooms:
            belief = cmap.room_category(rid)
            for c in categories:
                values[("p-room-category", rid, c)] = self.prune(belief[c])
        for rid in virtual:
            values |= {("p-room-category", rid, c): 0.0 for c in categories}
        for pid in placeholders:
            belief = cmap.placeholder_category(pid)
            for c in categories:
                values[("p-placeholder-category", pid, c)] = self.prune(belief.get(c, 0.0))

    def objects_in(self, labels: list[str], rooms: list[str], virtual: list[str],
                   categories: list[str], values: dict[Atom, float]) -> None:
        """`p-obj-in L R C` for every label and room, known or virtual (the prior): only
        the target, and supports the target may be on in a room of C, are worth finding."""
        cmap = self.mind.cmap
        knowledge = cmap.knowledge
        for label in labels:
            prior = cmap.p_any(label, knowledge.total_room_lambda(label))
            for rid in [*rooms, *virtual]:
                # a known room: the target outside its known supports (their share is in
                # p-find-on), the supports not found yet counted by the looks for them
                p = cmap.p_object_in_room_per_category(label, rid) if rid in rooms else prior
                for c in categories:
                    k = knowledge.category_index(c)
                    useful = label == self.task.target or self.support_useful(label, c)
                    p_in = self.prune(p[k]) if useful else 0.0
                    values[("p-obj-in", label, rid, c)] = self.restrict(c, p_in)

    def objects_on(self, label: str, labels: list[str], categories: list[str],
                   values: dict[Atom, float]) -> None:
        """`p-obj-on L S C`: the prior of `label` on (and in) any support of each label S in
        a room of C (0 where the knowledge relates them not)."""
        cmap = self.mind.cmap
        knowledge = cmap.knowledge
        supports = knowledge.support_relations(label)
        for support in labels:
            # on it and in it (`support_lambda`: zeros where the knowledge lists neither)
            p = cmap.p_any(label, knowledge.support_lambda(label, support)) \
                if support in supports else np.zeros(len(knowledge.categories))
            for c in categories:
                k = knowledge.category_index(c)
                values[("p-obj-on", label, support, c)] = self.restrict(c, self.prune(p[k]))

    def find_on(self, labels: list[str], objects: list[str], virtual: list[str],
                values: dict[Atom, float]) -> None:
        """`p-find-on L S`: the chance a search on S finds the L the plan assumed there. The
        assumption's `p-obj-on` is the prior for any support of S's label in a room of the
        category; this object's own looks (searches, glimpses) are in the share of L on it
        still unseen, so a desk searched once is not planned as if it never had been."""
        for label in labels:
            rate = values[("p-detect", label, "on")]
            for oid in [*objects, *virtual]:
                share = self.unseen_share(label, oid) if oid in self.mind.objects else 1.0
                values[("p-find-on", label, oid)] = round(rate * share, 6)

    def unseen_share(self, label: str, oid: str) -> float:
        """P(L on `oid` now) over its prior: Poisson thinning by the looks at it so far,
        averaged over the room's category belief (1 when nothing has looked at it)."""
        cmap = self.mind.cmap
        obj = self.mind.objects[oid]
        if obj.label not in cmap.knowledge.support_relations(label):
            return 1.0
        if all(cmap.objects.remaining(where, label) >= 1.0
               for where in support_spaces(self.mind, label, oid)) \
                or not cmap.graph.has_room(obj.room):
            return 1.0
        lam = cmap.knowledge.support_lambda(label, obj.label)
        prior = float(cmap.room_marginal(obj.room) @ cmap.p_any(label, lam))
        if prior <= 0.0:
            return 1.0
        return min(1.0, p_at_support(self.mind, label, oid, self.another(label)) / prior)

    def settled_on(self, label: str, oid: str) -> bool:
        """The map's belief that `label` is on the known object `oid` (its lambda thinned by
        the searches and glimpses there, over the room's category belief) is below the
        planner's threshold: the `p-obj-on` numbers are per support label and category, so
        this instance's own evidence reaches the planner as "settled"."""
        cmap = self.mind.cmap
        if self.mind.objects[oid].label not in cmap.knowledge.support_relations(label):
            return False
        if all(cmap.objects.remaining(where, label) >= 1.0
               for where in support_spaces(self.mind, label, oid)):
            return False
        return p_at_support(self.mind, label, oid, self.another(label)) \
            < self.config.min_probability

    def another(self, label: str) -> bool:
        """The task wants one more `label` beyond those it reported (it counts every
        instance): a place where one was found is not certain to hold another."""
        return label == self.task.target and bool(self.task.exclude)

    def could_hold(self, room: str) -> bool:
        """Under some category, the target may still be in `room` (on its known supports
        included) with at least `min_probability`, after the looks there so far."""
        cmap = self.mind.cmap
        if not cmap.graph.has_room(room):
            return False
        p = cmap.p_object_at_per_category(self.task.target, room,
                                           another=self.another(self.task.target))
        return float(np.max(p)) >= self.config.min_probability

    def support_useful(self, support: str, category: str) -> bool:
        """Finding `support` in a room of `category` helps only if the target may be on it."""
        knowledge = self.mind.cmap.knowledge
        if support not in knowledge.support_relations(self.task.target):
            return False
        lam = knowledge.support_lambda(self.task.target, support)
        p = float(self.mind.cmap.p_any(self.task.target, lam[knowledge.category_index(category)]))
        return p >= self.config.min_probability

    def prune(self, p: float) -> float:
        """Probabilities below `min_probability` become 0: the planner drops such actions."""
        return float(p) if p >= self.config.min_probability else 0.0

    def restrict(self, category: str, p: float) -> float:
        """With a task's room category, every other category's number is 0 (the task asks
        for a room of that category only)."""
        wanted = self.task.category
        return p if wanted is None or wanted == category else 0.0
